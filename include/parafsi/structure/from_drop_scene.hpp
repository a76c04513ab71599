/// \file from_drop_scene.hpp
/// The structure assembly of a parachute drop scene (model/drop_scene.hpp): nodes with
/// their point masses, the canopy's triangles with the cut pattern as reference and
/// the per-element warp direction, one cable part per kind (suspension lines, riser,
/// skirt tape, vent tape, radial bands) and the payload attachment, gravity set and
/// the assembly finalized. Part order: 0 membrane, 1–5 cables in that order, 6 payload
/// (`drop_part`); reach the parts by name with `canopy(a)`, `suspension_lines(a)`,
/// `riser(a)`, `skirt_tape(a)`, `vent_tape(a)`, `radial_bands(a)` and `payload(a)`
/// (`payload(a).body()` is the payload's rigid body), const or not, on the assembly or
/// on `stepper.structure()`:
///
///   auto chute = structure::make_drop_assembly(scene, 0.05);   // a structure::drop_assembly
///   const double F = structure::riser(chute).tension(chute.node_set(), 0);
///   const Eigen::Vector3d x = structure::payload(chute).body().mass_centre();
#pragma once
#include <concepts>
#include <cstddef>
#include <type_traits>
#include <utility>

#include "../model/drop_scene.hpp"
#include "structure.hpp"

namespace parafsi::structure {

inline auto make_drop_assembly(const model::drop_scene& s, double membrane_damping) {
  nodes nd;
  for (std::size_t i = 0; i < s.positions.size(); ++i) nd.add(s.positions[i], s.velocities[i], s.point_mass[i]);
  triangle_mesh tm;
  tm.triangles = s.triangles;
  tm.reference = s.reference;
  tm.warp_per_element = s.warp;
  const auto& m = s.moduli;
  membrane_tri membrane{tm, material::fabric<>{m.E11, m.E22, m.nu12, m.G12, m.areal_density, m.thickness},
                        membrane_options{membrane_damping}};
  auto part = [&](model::cable_kind k) {
    const auto& cs = s.cable(k);
    return cable{line_mesh{cs.segments, cs.rest_length},
                 material::cable{cs.material.EA(), cs.material.mass_per_length, cs.material.damping_ratio, 0.0}};
  };
  attachment body{rigid_body{rigid_body::cuboid(s.payload.mass, s.payload.size), s.payload.position, s.payload.attitude,
                             s.payload.velocity}};
  for (const auto& a : s.attachments) body.attach(a.node, a.r_body);
  assembly chute{std::move(nd),
                 std::move(membrane),
                 part(model::cable_kind::suspension_line),
                 part(model::cable_kind::riser),
                 part(model::cable_kind::skirt_tape),
                 part(model::cable_kind::vent_tape),
                 part(model::cable_kind::radial_band),
                 std::move(body)};
  chute.integrator().gravity = {0, 0, -s.params.gravity};
  chute.finalize();
  return chute;
}

/// The assembly type `make_drop_assembly` returns.
using drop_assembly = decltype(make_drop_assembly(std::declval<const model::drop_scene&>(), 0.0));

/// Part indices of a `drop_assembly` (the order of `make_drop_assembly`).
namespace drop_part {
inline constexpr std::size_t canopy = 0, suspension_lines = 1, riser = 2, skirt_tape = 3, vent_tape = 4,
                             radial_bands = 5, payload = 6;
}  // namespace drop_part

namespace detail {
template <class A>
concept drop_assembly_ref = std::same_as<std::remove_const_t<A>, drop_assembly>;
}  // namespace detail

/// The canopy membrane (`membrane_tri`).
template <detail::drop_assembly_ref A>
auto& canopy(A& a) noexcept {
  return a.template part<drop_part::canopy>();
}
/// The suspension lines (`cable`; one segment chain per line, confluence to skirt).
template <detail::drop_assembly_ref A>
auto& suspension_lines(A& a) noexcept {
  return a.template part<drop_part::suspension_lines>();
}
/// The riser (`cable`; its last segment ends at the payload).
template <detail::drop_assembly_ref A>
auto& riser(A& a) noexcept {
  return a.template part<drop_part::riser>();
}
/// The skirt tape (`cable`).
template <detail::drop_assembly_ref A>
auto& skirt_tape(A& a) noexcept {
  return a.template part<drop_part::skirt_tape>();
}
/// The vent tape (`cable`).
template <detail::drop_assembly_ref A>
auto& vent_tape(A& a) noexcept {
  return a.template part<drop_part::vent_tape>();
}
/// The radial bands (`cable`).
template <detail::drop_assembly_ref A>
auto& radial_bands(A& a) noexcept {
  return a.template part<drop_part::radial_bands>();
}
/// The payload (`attachment`); `payload(a).body()` is its rigid body.
template <detail::drop_assembly_ref A>
auto& payload(A& a) noexcept {
  return a.template part<drop_part::payload>();
}

}  // namespace parafsi::structure
