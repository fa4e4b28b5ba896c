// lugrip — model-based slip detection, slip avoidance and pivoting for force/torque fingertips.
// The real-time core (target lugrip::core): what a robot's control loop needs. The simulator is
// in lugrip/sim.hpp (lugrip::sim), the identification cost in lugrip/identification.hpp
// (lugrip::identification).
#pragma once

#include "lugrip/contact.hpp"
#include "lugrip/grasp_controller.hpp"
#include "lugrip/limit_surface.hpp"
#include "lugrip/observer.hpp"
#include "lugrip/params.hpp"
#include "lugrip/sensor_frame.hpp"
#include "lugrip/slider_model.hpp"
#include "lugrip/slip_control.hpp"
#include "lugrip/status.hpp"
#include "lugrip/version.hpp"
