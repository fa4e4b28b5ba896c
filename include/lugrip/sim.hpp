// lugrip — the grasp simulator (target lugrip::sim): plants and the closed loop.
#pragma once

#include "lugrip/closed_loop.hpp"
#include "lugrip/grasp_plant.hpp"
#include "lugrip/lugrip.hpp"
