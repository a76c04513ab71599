/// \file from_drop_scene.hpp
/// The structure assembly of a parachute drop scene (model/drop_scene.hpp): nodes with
/// their point masses, the canopy's triangles with the cut pattern as reference and
/// the per-element warp direction, one cable part per kind (suspension lines, riser,
/// skirt tape, vent tape, radial bands) and the payload attachment, gravity set and
/// the assembly finalized. Part order: 0 membrane, 1–5 cables in that order, 6 payload.
#pragma once
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
  attachment payload{rigid_body{rigid_body::cuboid(s.payload.mass, s.payload.size), s.payload.position,
                                s.payload.attitude, s.payload.velocity}};
  for (const auto& a : s.attachments) payload.attach(a.node, a.r_body);
  assembly chute{std::move(nd),
                 std::move(membrane),
                 part(model::cable_kind::suspension_line),
                 part(model::cable_kind::riser),
                 part(model::cable_kind::skirt_tape),
                 part(model::cable_kind::vent_tape),
                 part(model::cable_kind::radial_band),
                 std::move(payload)};
  chute.integrator().gravity = {0, 0, -s.params.gravity};
  chute.finalize();
  return chute;
}

}  // namespace parafsi::structure
