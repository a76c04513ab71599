/// \file membrane_coupling.hpp
/// What the membrane couplings (coupling::penalty, coupling::embedded) share: the
/// porosity law and options with their validation, the coupled triangles (every
/// 3-corner membrane part of the assembly, or the user's list given to couple()),
/// their attach checks, and the "attached" guard of the stepper hooks.
#pragma once
#include <array>
#include <cstddef>
#include <type_traits>
#include <utility>
#include <vector>

#include "../../core/config.hpp"
#include "../../core/error.hpp"
#include "../kinds.hpp"

namespace parafsi::coupling::detail {

using triangle = std::array<index_t, 3>;

/// Append the elements of every 3-corner membrane part of the assembly to `tris`.
template <class Asm>
void collect_triangles(const Asm& s, std::vector<triangle>& tris) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (
        (void)[&] {
          const auto& p = s.template part<I>();
          using P = std::remove_cvref_t<decltype(p)>;
          if constexpr (requires {
                          P::corners;
                          p.element(index_t(0));
                        }) {
            if constexpr (P::corners == 3)
              for (index_t e = 0; e < p.size(); ++e) tris.push_back(p.element(e));
          }
        }(),
        ...);
  }
  (std::make_index_sequence<Asm::part_count>{});
}

/// Base of a membrane coupling `Derived` with porosity law `Porosity` and options
/// `Options` (each with validate()).
template <class Derived, class Porosity, class Options>
class membrane_coupling {
 public:
  using policy_kind = kind::coupling;
  using porosity_type = Porosity;
  static constexpr bool active = true;

  membrane_coupling() { opt_.validate(); }
  explicit membrane_coupling(Porosity por, Options opt = {}) : por_(por), opt_(opt) {
    por_.validate();
    opt_.validate();
  }

  /// Couple only these triangles (default: every membrane_tri part of the assembly).
  Derived& couple(std::vector<triangle> triangles) {
    user_tris_ = std::move(triangles);
    have_user_tris_ = true;
    return static_cast<Derived&>(*this);
  }

  const Porosity& porosity() const noexcept { return por_; }
  const Options& options() const noexcept { return opt_; }
  Options& options() noexcept { return opt_; }

 protected:
  /// Finalize the assembly if needed and return the coupled triangles, each node
  /// checked to exist.
  template <class Asm>
  std::vector<triangle> attach_triangles(Asm& s) const {
    auto& nd = s.node_set();
    if (nd.needs_finalize()) s.finalize();
    std::vector<triangle> tris = user_tris_;
    if (!have_user_tris_) collect_triangles(s, tris);
    for (std::size_t e = 0; e < tris.size(); ++e)
      for (int a = 0; a < 3; ++a)
        require(tris[e][std::size_t(a)] >= 0 && tris[e][std::size_t(a)] < nd.size(), "coupling::", Derived::name(),
                ": triangle ", e, " names node ", tris[e][std::size_t(a)], " outside [0, ", nd.size(), ")");
    return tris;
  }
  void require_attached() const {
    require(attached_, "coupling::", Derived::name(), ": not attached (use it through explicit_stepper)");
  }

  Porosity por_{};
  Options opt_{};
  std::vector<triangle> user_tris_;
  bool have_user_tris_ = false;
  bool attached_ = false;
};

}  // namespace parafsi::coupling::detail
