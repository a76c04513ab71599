/// \file fields.hpp
/// Field tags of the fluid solver's cell arrays (structure-of-arrays storage, one
/// array per tag; core/soa.hpp) and the field lists of its storages:
///   conserved U = (ρ, ρu, ρv, ρw, E),  primitive W = (ρ, u, v, w, p),
///   viscous scratch (box-frame velocity, T, transport coefficients, face fluxes),
///   turbulence (μ_t, wall distance), sources (per unit volume and time) and sponge σ.
/// Tags with a `name` are written by the checkpoint and field output under that name.
#pragma once
#include "../core/meta.hpp"

namespace parafsi::fluid {

namespace field {
// Conserved variables.
struct rho {
  static constexpr const char* name = "rho";
};
struct mx {
  static constexpr const char* name = "mx";
};
struct my {
  static constexpr const char* name = "my";
};
struct mz {
  static constexpr const char* name = "mz";
};
struct E {
  static constexpr const char* name = "E";
};
// Primitive variables.
struct u {
  static constexpr const char* name = "u";
};
struct v {
  static constexpr const char* name = "v";
};
struct w {
  static constexpr const char* name = "w";
};
struct p {
  static constexpr const char* name = "p";
};
// Viscous scratch: box-frame velocity, temperature, transport coefficients.
struct ub0 {};
struct ub1 {};
struct ub2 {};
struct T {};
struct mu_eff {};
struct k_eff {};
// Viscous face fluxes of one axis (at the face's high cell) and their per-cell sums.
struct fv0 {};
struct fv1 {};
struct fv2 {};
struct fv3 {};
struct av0 {};
struct av1 {};
struct av2 {};
struct av3 {};
// Turbulence.
struct mu_t {
  static constexpr const char* name = "mu_t";
};
struct wall_distance {
  static constexpr const char* name = "wall_distance";
};
// Sources (per unit volume and time).
struct s_mx {
  static constexpr const char* name = "s_mx";
};
struct s_my {
  static constexpr const char* name = "s_my";
};
struct s_mz {
  static constexpr const char* name = "s_mz";
};
struct s_E {
  static constexpr const char* name = "s_E";
};
struct s_rho {
  static constexpr const char* name = "s_rho";
};
struct sponge_sigma {};
}  // namespace field

using conserved_fields = meta::list<field::rho, field::mx, field::my, field::mz, field::E>;
using primitive_fields = meta::list<field::rho, field::u, field::v, field::w, field::p>;
using viscous_fields = meta::list<field::ub0, field::ub1, field::ub2, field::T, field::mu_eff, field::k_eff, field::fv0,
                                  field::fv1, field::fv2, field::fv3, field::av0, field::av1, field::av2, field::av3>;
using source_fields = meta::list<field::s_mx, field::s_my, field::s_mz, field::s_E, field::s_rho>;

}  // namespace parafsi::fluid
