/// \file suspension_lines.hpp
/// Suspension lines, confluence and riser (plain data, no solver types), and the cord
/// and tape specifications the scene uses.
///
/// Geometry (canopy frame: axis +z, confluence below the canopy): one line per
/// attachment node (the skirt corners of flat_circular_canopy.hpp), each straight from its
/// attachment to the confluence point on the axis, rest length Ls split into n equal
/// segments. The confluence sits on the axis at
///     z_c = mean_k ( z_k − √(Ls² − ρ_k²) ),   ρ_k = distance of attachment k from the axis,
/// so every line of a symmetric canopy is exactly Ls long and unstressed (requires
/// Ls > ρ_k). The riser runs from the confluence straight down the axis, rest length Lr in
/// n_r segments, to the hanging-point node (to be attached to the payload at r_T).
///
/// Stiffness (Eq. 5, T = (EA/L0) max(0, L − L0)): the paper gives no line data, so
/// EA is the secant stiffness to break, EA ≈ F_break / ε_break, the same rule as the fabric
/// moduli (fabric_catalogue.hpp); uncertain by up to a factor of 2 (nylon cord stiffens with
/// load), hence a sensitivity parameter of the drop. Specifications:
///   - MIL-C-5040 Type I nylon cord: 95 lb (423 N) minimum break, ≈ 30 % elongation,
///     ≈ 1.6 g/m → EA ≈ 1.41 kN (the paper's 1 m canopy: a 1.8 kg payload gives opening
///     loads of tens of N, well inside a 95 lb line);
///   - MIL-C-5040 Type III ("550 cord"): 550 lb (2447 N), ≈ 30 %, ≈ 6.6 g/m → EA ≈ 8.16 kN
///     (the C-9 variant);
///   - tapes (skirt/vent tape, radial bands): the paper gives none; assumed ½-in nylon
///     tape, 2.22 kN (500 lb) at 25 %, ≈ 5 g/m → EA ≈ 8.9 kN (paper canopy), 1-in tape
///     4.45 kN (1000 lb) at 25 %, ≈ 12 g/m → EA ≈ 17.8 kN (C-9);
///   - riser: sized to carry all N lines, EA = N·EA_line, ρ_l = N·ρ_l,line (`combined`).
/// Cable damping ratio ξ = 0.1 (methods note §10 default) for all.
#pragma once
#include <array>
#include <cmath>
#include <span>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "../core/config.hpp"
#include "../core/error.hpp"

namespace parafsi::model {

/// A cord or tape: what structure::material::cable takes, with its origin.
struct line_spec {
  std::string_view name;
  double break_strength = 0;   ///< N
  double elongation = 0;       ///< at break, fraction
  double mass_per_length = 0;  ///< kg/m
  double damping_ratio = 0.1;  ///< ξ
  double stiffness_scale = 1;  ///< multiplies EA (sensitivity studies)
  /// Secant axial stiffness F_break/ε_break (N), times stiffness_scale.
  double EA() const { return stiffness_scale * break_strength / elongation; }
  void validate(std::string_view what) const {
    require(break_strength > 0 && std::isfinite(break_strength), "model::line_spec (", what,
            "): break strength must be > 0, got ", break_strength);
    require(elongation > 0 && std::isfinite(elongation), "model::line_spec (", what,
            "): elongation at break must be > 0, got ", elongation);
    require(mass_per_length >= 0 && std::isfinite(mass_per_length), "model::line_spec (", what,
            "): mass per length must be >= 0, got ", mass_per_length);
    require(damping_ratio >= 0 && damping_ratio < 1, "model::line_spec (", what,
            "): damping ratio must be in [0, 1), got ", damping_ratio);
    require(stiffness_scale > 0 && std::isfinite(stiffness_scale), "model::line_spec (", what,
            "): stiffness scale must be > 0, got ", stiffness_scale);
  }
  /// n of these in parallel (a riser carrying n lines).
  line_spec combined(int n) const {
    line_spec s = *this;
    s.name = "combined lines";
    s.break_strength *= n;
    s.mass_per_length *= n;
    return s;
  }
};

namespace line_specs {
inline constexpr line_spec mil_c_5040_type_i{"MIL-C-5040 Type I nylon cord (95 lb)", 423.0, 0.30, 1.6e-3, 0.1, 1.0};
inline constexpr line_spec mil_c_5040_type_iii{
    "MIL-C-5040 Type III nylon cord (550 lb)", 2447.0, 0.30, 6.6e-3, 0.1, 1.0};
inline constexpr line_spec tape_half_inch{"1/2-in nylon tape, 500 lb (assumed)", 2224.0, 0.25, 5.0e-3, 0.1, 1.0};
inline constexpr line_spec tape_one_inch{"1-in nylon tape, 1000 lb (assumed)", 4448.0, 0.25, 12.0e-3, 0.1, 1.0};
}  // namespace line_specs

struct suspension_parameters {
  double line_length = 1.0;    ///< Ls (m), attachment → confluence
  int line_segments = 10;      ///< segments per line
  double riser_length = 0.08;  ///< Lr (m), confluence → hanging point
  int riser_segments = 1;

  void validate() const {
    require(line_length > 0 && std::isfinite(line_length), "model::suspension_lines: line length Ls must be > 0, got ",
            line_length);
    require(line_segments >= 1, "model::suspension_lines: need at least 1 segment per line, got ", line_segments);
    require(riser_length > 0 && std::isfinite(riser_length), "model::suspension_lines: riser length must be > 0, got ",
            riser_length);
    require(riser_segments >= 1, "model::suspension_lines: need at least 1 riser segment, got ", riser_segments);
  }
};

struct suspension_mesh {
  std::vector<std::vector<index_t>> lines;  ///< line k: attachment k → confluence (node path)
  std::vector<index_t> riser;               ///< confluence → hanging point
  index_t confluence = -1, hanging_point = -1;
  std::vector<std::array<index_t, 2>> line_segments, riser_segments;
  std::vector<double> line_rest_length, riser_rest_length;  ///< per segment (m)
};

/// Append the line and riser nodes to `positions` (canopy frame, axis +z) and return the
/// connectivity. `attachments` are node ids already in `positions`.
inline suspension_mesh suspension_lines(std::vector<Eigen::Vector3d>& positions, std::span<const index_t> attachments,
                                        const suspension_parameters& p) {
  p.validate();
  require(!attachments.empty(), "model::suspension_lines: no attachment nodes");
  double zc = 0;
  for (const index_t a : attachments) {
    require(a >= 0 && a < index_t(positions.size()), "model::suspension_lines: attachment node ", a, " outside [0, ",
            positions.size(), ")");
    const Eigen::Vector3d& x = positions[std::size_t(a)];
    const double rho = x.head<2>().norm();
    require(rho < p.line_length, "model::suspension_lines: line length Ls = ", p.line_length,
            " m is shorter than the attachment radius ", rho, " m of node ", a);
    zc += x.z() - std::sqrt(p.line_length * p.line_length - rho * rho);
  }
  zc /= double(attachments.size());
  suspension_mesh s;
  auto add = [&](const Eigen::Vector3d& x) {
    positions.push_back(x);
    return index_t(positions.size()) - 1;
  };
  const Eigen::Vector3d xc(0, 0, zc);
  s.confluence = add(xc);
  for (const index_t a : attachments) {
    const Eigen::Vector3d xa = positions[std::size_t(a)];
    std::vector<index_t> path{a};
    for (int q = 1; q < p.line_segments; ++q) path.push_back(add(xa + (xc - xa) * (double(q) / p.line_segments)));
    path.push_back(s.confluence);
    for (std::size_t q = 0; q + 1 < path.size(); ++q) {
      s.line_segments.push_back({path[q], path[q + 1]});
      s.line_rest_length.push_back(p.line_length / p.line_segments);
    }
    s.lines.push_back(std::move(path));
  }
  s.riser.push_back(s.confluence);
  for (int q = 1; q <= p.riser_segments; ++q)
    s.riser.push_back(add(xc - Eigen::Vector3d(0, 0, p.riser_length * double(q) / p.riser_segments)));
  s.hanging_point = s.riser.back();
  for (std::size_t q = 0; q + 1 < s.riser.size(); ++q) {
    s.riser_segments.push_back({s.riser[q], s.riser[q + 1]});
    s.riser_rest_length.push_back(p.riser_length / p.riser_segments);
  }
  return s;
}

}  // namespace parafsi::model
