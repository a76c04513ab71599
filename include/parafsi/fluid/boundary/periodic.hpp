/// \file periodic.hpp
/// Periodic pairing of the two faces of an axis: ghosts copy the cells of the
/// opposite side. Must be set on both faces of the axis.
#pragma once

namespace parafsi::boundary {
struct periodic {
  static constexpr const char* name() noexcept { return "periodic"; }
};
}  // namespace parafsi::boundary
