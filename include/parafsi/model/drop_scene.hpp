/// \file drop_scene.hpp
/// The parachute–payload drop scene as plain data (no solver types): the paper's
/// section 4 set-up (`drop_scene_parameters::paper()`) and the C-9 validation canopy of
/// its section 3 (`drop_scene_parameters::c9()`), assembled from flat_circular_canopy,
/// packed_shape, suspension_lines, payload and the fabric catalogue.
///
/// Paper values (Table 3 and §4.1): released at rest from 35 m, flight-path angle 90°,
/// ρ = 1.18 kg/m³, p = 101325 Pa, μ = 1.79e-5 Pa s, g = 9.81 m/s², payload 1.8 kg;
/// 8 gores, D0 = 1.0 m, Dv = 0.1 D0, Ls = D0 (8 lines to one confluence), riser
/// Lr = 0.08 Ls, skirt and vent tapes, 4 radial bands through the vent; fabric of Table 2.
/// Values the paper does not give are chosen and documented in the builders' headers
/// and docs/model.md (fabric moduli, line/tape/riser stiffness and mass, payload size,
/// packed shape, element size).
///
/// Frame: the scene is built in the canopy frame (vent centre at the origin, axis +z
/// from the payload to the canopy), rotated so the axis points against the flight
/// direction v̂ = (cos γ, 0, −sin γ) (γ the flight-path angle, 90° = straight down,
/// gravity −z), and translated so the payload mass centre is at (0, 0, release height).
/// All nodes and the payload start with velocity V v̂ (V the initial speed), every line
/// straight and exactly Ls long (suspension_lines.hpp), the canopy stress-free in its packed
/// shape; the air (the drop program's) starts at rest. With `packed_shape::bundle` this is a
/// bag deployment at line stretch and V is the speed at line stretch.
///
/// Use with the structure module: `nodes.add(positions[i], velocities[i], point_mass[i])`;
/// `triangle_mesh{triangles, reference, warp}` with
/// `fabric<>{m.E11, m.E22, m.nu12, m.G12, m.areal_density, m.thickness}` (m = moduli);
/// one `cable` part per non-empty cable set, `line_mesh{segments, rest_length}` with
/// `material::cable{spec.EA(), spec.mass_per_length, spec.damping_ratio, 0}`; the payload
/// as in payload.hpp with `attach(a.node, a.r_body)` for each attachment. `point_mass`
/// is zero everywhere (the parts lump their own masses); `lumped_mass` is what they will
/// lump (ρ_A A0/3 per triangle corner, ρ_l L0/2 per segment end), for checks.
#pragma once
#include <array>
#include <cmath>
#include <numbers>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "../core/config.hpp"
#include "../core/error.hpp"
#include "fabric_catalogue.hpp"
#include "flat_circular_canopy.hpp"
#include "packed_shape.hpp"
#include "payload.hpp"
#include "suspension_lines.hpp"

namespace parafsi::model {

/// Kinds of line elements (the paper's Table 1: vent tape, lines and riser are discrete
/// cables, the skirt tape a seatbelt; the radial bands are not listed and are cables here).
enum class cable_kind : int { suspension_line = 0, riser = 1, skirt_tape = 2, vent_tape = 3, radial_band = 4 };
inline constexpr int cable_kind_count = 5;
inline constexpr const char* cable_kind_name(cable_kind k) {
  switch (k) {
    case cable_kind::suspension_line: return "suspension_line";
    case cable_kind::riser: return "riser";
    case cable_kind::skirt_tape: return "skirt_tape";
    case cable_kind::vent_tape: return "vent_tape";
    default: return "radial_band";
  }
}

struct drop_scene_parameters {
  std::string name = "paper";
  // Table 3
  double release_height = 35.0;     ///< payload mass centre height (m)
  double initial_speed = 0.0;       ///< m/s, of every node and the payload (with a bundle: at line stretch)
  double flight_path_angle = 90.0;  ///< degrees below the horizontal
  double air_density = 1.18;        ///< kg/m³
  double air_pressure = 101325.0;   ///< Pa
  double air_viscosity = 1.79e-5;   ///< Pa s
  double gravity = 9.81;            ///< m/s²
  // §4.1
  canopy_parameters canopy{};      ///< 8 gores, D0 = 1 m, Dv = 0.1 D0
  double line_length_ratio = 1.0;  ///< Ls / D0
  double riser_ratio = 0.08;       ///< Lr / Ls
  int line_segments = 10;
  int riser_segments = 1;
  std::string fabric = "mat544";
  moduli_options moduli{};
  line_spec line = line_specs::mil_c_5040_type_i;
  line_spec skirt_tape = line_specs::tape_half_inch;
  line_spec vent_tape = line_specs::tape_half_inch;
  line_spec band = line_specs::tape_half_inch;
  double riser_strength_factor = 0;  ///< riser = this many lines in parallel (0: the number of lines)
  payload_parameters payload{};
  packed_shape shape{};  ///< reduced radius, s = 0.2

  double line_length() const { return line_length_ratio * canopy.nominal_diameter; }
  double riser_length() const { return riser_ratio * line_length(); }
  /// Nominal area S0 = π D0²/4 (for C_D).
  double nominal_area() const { return 0.25 * std::numbers::pi * canopy.nominal_diameter * canopy.nominal_diameter; }

  void validate() const {
    canopy.validate();
    require(std::isfinite(release_height), "model::drop_scene: release height must be finite, got ", release_height);
    require(initial_speed >= 0 && std::isfinite(initial_speed), "model::drop_scene: initial speed must be >= 0, got ",
            initial_speed);
    require(flight_path_angle >= -90 && flight_path_angle <= 90,
            "model::drop_scene: flight-path angle must be in [-90, 90] degrees, got ", flight_path_angle);
    require(air_density > 0 && std::isfinite(air_density), "model::drop_scene: air density must be > 0, got ",
            air_density);
    require(air_pressure > 0 && std::isfinite(air_pressure), "model::drop_scene: air pressure must be > 0, got ",
            air_pressure);
    require(air_viscosity >= 0 && std::isfinite(air_viscosity), "model::drop_scene: air viscosity must be >= 0, got ",
            air_viscosity);
    require(gravity >= 0 && std::isfinite(gravity), "model::drop_scene: gravity must be >= 0, got ", gravity);
    require(line_length_ratio > 0 && std::isfinite(line_length_ratio),
            "model::drop_scene: line length ratio Ls/D0 must be > 0, got ", line_length_ratio);
    require(riser_ratio > 0 && std::isfinite(riser_ratio), "model::drop_scene: riser ratio Lr/Ls must be > 0, got ",
            riser_ratio);
    require(riser_strength_factor >= 0, "model::drop_scene: riser strength factor must be >= 0, got ",
            riser_strength_factor);
    line.validate("suspension line");
    skirt_tape.validate("skirt tape");
    vent_tape.validate("vent tape");
    band.validate("radial band");
    payload.validate();
    shape.validate();
  }

  /// The paper's section 4 scene (the defaults).
  static drop_scene_parameters paper(std::string_view fabric_name = "mat544") {
    drop_scene_parameters p;
    p.fabric = std::string(fabric_name);
    return p;
  }

  /// The C-9 validation canopy (paper §3): 28 gores, 28 ft = 8.534 m, deployed at
  /// 13.4 m/s. Chosen (the paper defers to Lee 1984 / Lee et al. 1997 and gives none):
  /// vent 0.1 D0 as the paper canopy; Ls = D0 (Knacke's usual
  /// 0.85–1.15 D0); riser 0.08 Ls; MIL-C-5040 Type III lines, 1-in tapes; MIL-C-7020
  /// Type I cloth; payload 90.7 kg (200 lb test weight), 0.4 × 0.3 × 0.8 m; flight path
  /// vertical; release height 300 m; packed shape reduced radius s = 0.1; element size
  /// D0/20.
  static drop_scene_parameters c9() {
    drop_scene_parameters p;
    p.name = "c9";
    p.release_height = 300.0;
    p.initial_speed = 13.4;
    p.flight_path_angle = 90.0;
    p.canopy.gores = 28;
    p.canopy.nominal_diameter = 28.0 * 0.3048;
    p.canopy.vent_ratio = 0.1;
    p.canopy.element_size = p.canopy.nominal_diameter / 20.0;
    p.line_length_ratio = 1.0;
    p.riser_ratio = 0.08;
    p.line_segments = 10;
    p.fabric = "c9_mil_c_7020";
    p.line = line_specs::mil_c_5040_type_iii;
    p.skirt_tape = p.vent_tape = p.band = line_specs::tape_one_inch;
    p.payload.mass = 90.7;
    p.payload.size = Eigen::Vector3d(0.4, 0.3, 0.8);
    p.shape = packed_shape::reduced_radius(0.1);
    return p;
  }
};

/// One cable part's data: segments, rest lengths and the material.
struct cable_set {
  cable_kind kind = cable_kind::suspension_line;
  line_spec material{};
  std::vector<std::array<index_t, 2>> segments;
  std::vector<double> rest_length;
  double total_rest_length() const {
    double L = 0;
    for (double l : rest_length) L += l;
    return L;
  }
};

struct attachment_point {
  index_t node;
  Eigen::Vector3d r_body;  ///< body coordinates, from the payload mass centre
};

struct drop_scene {
  drop_scene_parameters params;
  fabric_data fabric{};
  membrane_moduli moduli{};
  // Nodes (canopy nodes first, ids as in `canopy`; then confluence, line, riser nodes).
  std::vector<Eigen::Vector3d> positions, velocities;
  std::vector<Eigen::Vector3d> reference;  ///< stress-free positions of every node (canopy: the cut pattern)
  std::vector<double> point_mass;          ///< for nodes::add (zero: elements lump their own mass)
  std::vector<double> lumped_mass;         ///< what the parts will lump (diagnostics)
  // Membrane (one fabric).
  std::vector<std::array<index_t, 3>> triangles;
  std::vector<Eigen::Vector3d> warp;  ///< per triangle (world axes)
  std::vector<int> triangle_fabric;   ///< index into `fabrics` (all 0)
  std::vector<membrane_moduli> fabrics;
  // Lines.
  std::array<cable_set, cable_kind_count> cables;
  // Payload.
  payload_data payload;
  std::vector<attachment_point> attachments;
  // Tags and parts.
  canopy_mesh canopy;                                         ///< the canopy's own data (cut pattern, tags)
  suspension_mesh suspension;                                 ///< line / riser paths (node ids)
  index_t canopy_nodes = 0;                                   ///< nodes [0, canopy_nodes) are the canopy's
  Eigen::Quaterniond frame = Eigen::Quaterniond::Identity();  ///< canopy frame → world rotation
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();           ///< canopy frame origin in world

  index_t node_count() const { return index_t(positions.size()); }
  const cable_set& cable(cable_kind k) const { return cables[std::size_t(int(k))]; }
  double canopy_reference_area() const { return canopy.reference_area(); }
  /// ρ_A × reference area.
  double canopy_cloth_mass() const { return fabric.areal_density * canopy_reference_area(); }
  /// Σ lumped masses (cloth, tapes, bands, lines, riser) + payload.
  double total_mass() const {
    double m = payload.mass;
    for (double x : lumped_mass) m += x;
    return m;
  }
  /// Canopy axis in world (payload → canopy).
  Eigen::Vector3d axis() const { return frame * Eigen::Vector3d::UnitZ(); }
};

/// Assemble the scene of `p` (throws invalid_input naming a bad value).
inline drop_scene build_drop_scene(const drop_scene_parameters& p = drop_scene_parameters::paper()) {
  p.validate();
  drop_scene s;
  s.params = p;
  s.fabric = fabric(p.fabric);
  s.moduli = derived_moduli(s.fabric, p.moduli);
  s.fabrics = {s.moduli};
  s.canopy = flat_circular_canopy(p.canopy);
  const canopy_mesh& c = s.canopy;
  s.canopy_nodes = c.node_count();

  // Canopy frame: packed positions, then lines, riser.
  std::vector<Eigen::Vector3d> x = packed_positions(c, p.shape);
  suspension_parameters sp;
  sp.line_length = p.line_length();
  sp.line_segments = p.line_segments;
  sp.riser_length = p.riser_length();
  sp.riser_segments = p.riser_segments;
  s.suspension = suspension_lines(x, c.line_attachment, sp);
  const suspension_mesh& sm = s.suspension;

  s.payload = cuboid_payload(p.payload);
  const Eigen::Vector3d payload_local = x[std::size_t(sm.hanging_point)] - s.payload.hanging_point;

  // World placement.
  const double gam = p.flight_path_angle * std::numbers::pi / 180.0;
  const Eigen::Vector3d vhat(std::cos(gam), 0.0, -std::sin(gam));
  s.frame = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), -vhat);
  s.offset = Eigen::Vector3d(0, 0, p.release_height) - s.frame * payload_local;
  auto world = [&](const Eigen::Vector3d& y) -> Eigen::Vector3d { return s.frame * y + s.offset; };
  const Eigen::Vector3d v0 = p.initial_speed * vhat;
  const std::size_t n = x.size();
  s.positions.resize(n);
  s.reference.resize(n);
  s.velocities.assign(n, v0);
  s.point_mass.assign(n, 0.0);
  s.lumped_mass.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    s.positions[i] = world(x[i]);
    s.reference[i] = i < c.positions.size() ? world(c.positions[i]) : s.positions[i];
  }
  s.payload.position = Eigen::Vector3d(0, 0, p.release_height);
  s.payload.attitude = s.frame;
  s.payload.velocity = v0;
  s.attachments.push_back({sm.hanging_point, s.payload.hanging_point});

  // Membrane.
  s.triangles = c.triangles;
  s.triangle_fabric.assign(c.triangles.size(), 0);
  for (const auto& w : c.warp) s.warp.push_back(s.frame * w);
  for (const auto& t : c.triangles) {
    const double A = 0.5 * (c.positions[std::size_t(t[1])] - c.positions[std::size_t(t[0])])
                               .cross(c.positions[std::size_t(t[2])] - c.positions[std::size_t(t[0])])
                               .norm();
    for (const index_t a : t) s.lumped_mass[std::size_t(a)] += s.moduli.areal_density * A / 3.0;
  }

  // Cables (rest length: canopy cables from the cut pattern, lines/riser from their lengths).
  auto fill = [&](cable_kind k, const line_spec& spec, const std::vector<std::array<index_t, 2>>& segs,
                  const std::vector<double>* rest) {
    cable_set& cs = s.cables[std::size_t(int(k))];
    cs.kind = k;
    cs.material = spec;
    cs.segments = segs;
    for (std::size_t e = 0; e < segs.size(); ++e) {
      const double L0 = rest ? (*rest)[e]
                             : (c.positions[std::size_t(segs[e][1])] - c.positions[std::size_t(segs[e][0])]).norm();
      cs.rest_length.push_back(L0);
      s.lumped_mass[std::size_t(segs[e][0])] += 0.5 * spec.mass_per_length * L0;
      s.lumped_mass[std::size_t(segs[e][1])] += 0.5 * spec.mass_per_length * L0;
    }
  };
  const int nlines = int(sm.lines.size());
  line_spec riser = p.line.combined(p.riser_strength_factor > 0 ? int(std::lround(p.riser_strength_factor)) : nlines);
  riser.name = "riser (lines in parallel)";
  fill(cable_kind::suspension_line, p.line, sm.line_segments, &sm.line_rest_length);
  fill(cable_kind::riser, riser, sm.riser_segments, &sm.riser_rest_length);
  fill(cable_kind::skirt_tape, p.skirt_tape, c.skirt_tape, nullptr);
  fill(cable_kind::vent_tape, p.vent_tape, c.vent_tape, nullptr);
  fill(cable_kind::radial_band, p.band, c.band_segments, nullptr);
  return s;
}

}  // namespace parafsi::model
