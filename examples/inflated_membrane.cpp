// Clamped flat circular isotropic membrane under uniform pressure, brought to rest by
// damped explicit dynamics; the check is the Föppl–Hencky solution
// (include/parafsi/structure/reference/hencky.hpp).
//
//   inflated_membrane --radius 0.5 --thickness 1e-4 --E 1e9 --nu 0.3 --pressure 20
//                     --elements 20 --out membrane.csv [--element tri|quad]
//
// Prints `centre_deflection=<m>` (and Hencky's value for comparison) on stdout, writes
// `r,w` (ring radius, mean deflection of the ring) to --out, progress on stderr.
// --element tri (default): CST triangles on a ring mesh (6 N² triangles);
// --element quad: Belytschko–Tsay one-point quads on an O-grid (n = N rounded up to even:
// n² + 4n·m quads, about the node count of the triangle mesh); the CSV then holds the
// same N + 1 radii, each the mean deflection of the nodes nearest to that radius (the
// rim row: the rim nodes).
#include <CLI/CLI.hpp>

#include "cli_checks.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <parafsi/core/parallel.hpp>
#include <parafsi/io/checked_file.hpp>
#include <parafsi/model/disk_mesh.hpp>
#include <parafsi/model/disk_quad_mesh.hpp>
#include <parafsi/structure/assembly.hpp>
#include <parafsi/structure/membrane_quad.hpp>
#include <parafsi/structure/membrane_tri.hpp>
#include <parafsi/structure/reference/hencky.hpp>
#include <parafsi/structure/relax.hpp>

namespace st = parafsi::structure;
using parafsi::index_t;

int main(int argc, char** argv) {
  CLI::App app{"Clamped circular membrane under uniform pressure, relaxed to rest (Hencky check)"};
  double a = 0, h = 0, E = 0, nu = 0, p = 0, density = 1000.0, tol = 1e-12;
  int rings = 20, threads = 1;
  std::string out, element = "tri";
  app.add_option("--radius", a, "membrane radius A (m)")->required()->check(CLI::Range(1e-4, 1e3));
  app.add_option("--thickness", h, "thickness H (m)")->required()->check(CLI::Range(1e-7, 1.0));
  app.add_option("--E", E, "Young's modulus (Pa)")->required()->check(CLI::Range(1e3, 1e13));
  app.add_option("--nu", nu, "Poisson ratio in [0, 0.5)")->required()->check(CLI::Range(0.0, 0.4999));
  app.add_option("--pressure", p, "uniform pressure (Pa)")->required()->check(CLI::Range(1e-3, 1e8));
  app.add_option("--elements", rings, "radial divisions N (6 N^2 triangles)")
      ->check(CLI::Range(2, 400))
      ->capture_default_str();
  app.add_option("--density", density, "material density (kg/m^3); statics do not depend on it")
      ->check(CLI::Range(1e-3, 1e5))
      ->capture_default_str();
  app.add_option("--tolerance", tol, "stop when kinetic energy < tolerance x its peak")
      ->check(CLI::Range(1e-20, 1e-2))
      ->capture_default_str();
  app.add_option("--threads", threads, "OpenMP threads")->check(CLI::Range(1, 1024))->capture_default_str();
  app.add_option("--out", out, "CSV file (r,w)")->required();
  app.add_option("--element", element, "membrane element: tri (CST) or quad (Belytschko-Tsay)")
      ->check(CLI::IsMember({"tri", "quad"}))
      ->capture_default_str();
  if (int rc = 0; !examples::parse(app, argc, argv, rc)) return rc;

  try {
    // One run for either element part (same loads, damping, relaxation and output).
    auto run = [&](auto mem, const std::vector<Eigen::Vector3d>& positions, const std::vector<index_t>& rim,
                   index_t centre, std::size_t n_elements, const char* kind, const std::vector<int>& bin) -> int {
      st::nodes nd;
      for (const auto& x : positions) nd.add(x);
      for (auto i : rim) nd.pin(i);
      mem.set_pressure(p);
      st::assembly chute{std::move(nd), std::move(mem)};
      chute.integrator().gravity.setZero();

      // Hencky estimate of the radial stress sets the damping near critical for the
      // fundamental mode: ω₁ ≈ 2.405 √(σ h/ρ_A)/a.
      const auto ref = st::reference::hencky(nu);
      const double sigma_star = std::cbrt(E * p * p * a * a / (8.0 * h * h));
      const double omega1 = 2.405 * std::sqrt(ref.s0 * sigma_star * h / (density * h)) / a;
      chute.integrator().mass_damping = 2.0 * omega1;
      const double w_hencky = ref.coefficient * a * std::cbrt(p * a / (E * h));

      std::fprintf(stderr, "inflated_membrane: %zu %s, %ld nodes, dt = %.3e s, omega1 ~ %.3e rad/s\n", n_elements, kind,
                   long(positions.size()), chute.stable_dt(), omega1);
      st::relax_options ro;
      ro.tolerance = tol;
      ro.t_min = 2.0 * std::numbers::pi / omega1;
      ro.t_max = 400.0 / omega1;
      ro.report_every = 2000;
      const auto r = st::relax(chute, ro, [&](double t, double k, double kp) {
        std::fprintf(stderr, "  t = %.4e s  w0 = %.6e m  K/Kpeak = %.3e\n", t, chute.node_set().position(centre).z(),
                     k / kp);
      });
      if (!r.converged) {
        std::fprintf(stderr, "inflated_membrane: not at rest after t = %.3e s (K/Kpeak = %.3e)\n", r.time,
                     r.kinetic / r.peak);
        return 2;
      }
      const double w0 = chute.node_set().position(centre).z();
      std::fprintf(stderr, "inflated_membrane: at rest after %ld steps, t = %.4e s\n", r.steps, r.time);

      std::ostringstream f;  // written through io::checked_file below
      f.precision(10);
      f << "r,w\n" << 0.0 << "," << w0 << "\n";
      std::vector<double> sum(std::size_t(rings) + 1, 0.0), count(std::size_t(rings) + 1, 0.0);
      for (std::size_t i = 0; i < positions.size(); ++i) {
        sum[std::size_t(bin[i])] += chute.node_set().position(index_t(i)).z();
        count[std::size_t(bin[i])] += 1;
      }
      for (int k = 1; k <= rings; ++k) f << a * k / rings << "," << sum[std::size_t(k)] / count[std::size_t(k)] << "\n";
      parafsi::io::write_text_file(out, f.str());
      std::printf("centre_deflection=%.10g\n", w0);
      std::printf("hencky_centre_deflection=%.10g\n", w_hencky);
      std::printf("relative_error=%.6e\n", w0 / w_hencky - 1.0);
      return 0;
    };
    parafsi::parallel::set_threads(threads);
    const auto fabric = st::material::fabric<>::isotropic(E, nu, density * h, h);
    if (element == "quad") {
      const auto disk = parafsi::model::disk_quad_mesh(a, rings + rings % 2);
      st::quad_mesh mesh;
      mesh.quads = disk.quads;
      // Profile: node → nearest of the radii k a/N, k < N; the rim nodes alone → k = N.
      std::vector<int> bin;
      for (const auto& x : disk.positions)
        bin.push_back(std::min(rings - 1, int(std::lround(std::hypot(x.x(), x.y()) / a * rings))));
      for (auto i : disk.rim) bin[std::size_t(i)] = rings;
      return run(st::membrane_quad(mesh, fabric), disk.positions, disk.rim, disk.centre, disk.quads.size(), "quads",
                 bin);
    }
    const auto disk = parafsi::model::disk_mesh(a, rings);
    st::triangle_mesh mesh;
    mesh.triangles = disk.triangles;
    std::vector<int> bin;  // ring k holds 6k nodes, ring 0 the centre
    bin.push_back(0);
    for (int k = 1; k <= rings; ++k) bin.insert(bin.end(), std::size_t(6 * k), k);
    return run(st::membrane_tri(mesh, fabric), disk.positions, disk.rim, 0, disk.triangles.size(), "triangles", bin);
  } catch (const parafsi::error& e) {
    std::fprintf(stderr, "inflated_membrane: %s\n", e.what());
    return 1;
  }
}
