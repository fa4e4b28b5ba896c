// ClosedLoop::step() never allocates (plant, both observers, controller or baselines, schedule):
// this binary replaces the global operator new and counts calls while stepping.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>

#include "lugrip/closed_loop.hpp"

#include "counting_new.hpp"

using namespace lugrip;

TEST(NoAllocation, ClosedLoopStep) {
  for (PlantModel model : {PlantModel::Patch, PlantModel::Lumped}) {
    for (ControllerKind kind : {ControllerKind::Lugrip, ControllerKind::ConstantForce, ControllerKind::FrictionCone}) {
      ClosedLoopConfig c;
      c.plant.contact = object_params("plastic_bottle");
      c.plant.model = model;
      c.plant.object.mass = 0.3;
      c.plant.object.inertia = 1e-3;
      c.plant.object.cog_x = 0.005;
      c.plant.actuator.f_init = 2.0;
      c.plant.support = true;
      c.plant.drop.rotation_limit = INFINITY;
      c.plant.moves.push_back(GripperMove{0.2, 1.0, 0.02, 0.05});
      c.plant.disturbances.push_back(Disturbance{1.5, 0.3, PulseShape::HalfSine, 0.5, -2.0, 0.002, 0.0, 0.0});
      c.kind = kind;
      c.constant_force = 5.0;
      c.cone_release_rate = 1.0;
      c.schedule.push_back(ModeEvent{0.1, ModeAction::DynamicOff});
      c.schedule.push_back(ModeEvent{0.15, ModeAction::DynamicOn});
      c.schedule.push_back(ModeEvent{2.0, ModeAction::Pivot});
      c.schedule.push_back(ModeEvent{3.0, ModeAction::SlippingAvoidance});
      // every fault kind, so that injection is covered too
      for (int f = 0; f <= 9; ++f) {
        FaultSpec spec;
        spec.kind = static_cast<FaultKind>(f);
        spec.t_start = 0.3 + 0.3 * f;
        spec.duration = 0.2;
        spec.burst = 3;
        spec.every = 10;
        spec.force = 3.0;
        spec.torque = 0.01;
        spec.force_rate = 1.0;
        spec.time_constant = 0.1;
        c.faults.push_back(spec);
      }
      c.stuck_samples = 20;
      c.healthy_finger_fallback = model == PlantModel::Patch;  // both SlipControl paths
      ClosedLoop loop(c);  // allocates (construction)
      ClosedLoopSample s;
      const long before = lugrip_support::g_allocations.load();
      for (int n = 0; n < 2000; ++n) loop.step(s);  // 4 s: lift, push, pivot, back
      loop.reset();
      for (int n = 0; n < 500; ++n) loop.step(s);
      const long used = lugrip_support::g_allocations.load() - before;
      EXPECT_EQ(used, 0) << to_string(model) << " " << to_string(kind);
      EXPECT_TRUE(s.finite);  // outputs finite (NaN readings excepted while a fault acts)
    }
  }
}
