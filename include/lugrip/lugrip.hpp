// lugrip — model-based slip detection, slip avoidance and pivoting for force/torque fingertips.
#pragma once

#include "lugrip/closed_loop.hpp"
#include "lugrip/contact.hpp"
#include "lugrip/grasp_controller.hpp"
#include "lugrip/grasp_plant.hpp"
#include "lugrip/identification.hpp"
#include "lugrip/limit_surface.hpp"
#include "lugrip/observer.hpp"
#include "lugrip/params.hpp"
#include "lugrip/slider_model.hpp"
#include "lugrip/status.hpp"
#include "lugrip/version.hpp"
