/// \file fixed.hpp
/// A box that does not move (V = Ω = 0).
#pragma once
#include "../../core/policy.hpp"
#include "pose.hpp"

namespace parafsi::frame {

struct fixed {
  using policy_kind = kind::frame;
  static constexpr const char* name() noexcept { return "fixed"; }
  void plan(pose& p, double /*t*/, double /*dt*/) const {
    p.V.setZero();
    p.Omega.setZero();
  }
};

}  // namespace parafsi::frame
