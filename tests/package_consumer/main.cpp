// A downstream program: a Sod shock tube through the installed package.
#include <parafsi/parafsi.hpp>

#include <cstdio>

int main() {
  namespace pf = parafsi;
  auto grid = pf::fluid::rectilinear_grid::uniform({100, 2, 2}, {0, 0, 0}, {1, 0.02, 0.02});
  pf::fluid::solver s{grid, pf::boundary::set::all(pf::boundary::slip_wall{}), pf::flux::hllc{}};
  s.initialize([](const Eigen::Vector3d& x) {
    return x[0] < 0.5 ? pf::fluid::prim<double>{1.0, {0, 0, 0}, 1.0} : pf::fluid::prim<double>{0.125, {0, 0, 0}, 0.1};
  });
  while (s.time() < 0.2) s.step(std::min(s.stable_dt(0.5), 0.2 - s.time()));
  const double rho = s.primitive(50, 0, 0).rho;
  std::printf("consumer: %s, rho(0.505) = %.4f after %ld steps\n", s.name().c_str(), rho, s.steps());
  return (rho > 0.2 && rho < 0.5) ? 0 : 1;  // inside the contact/shock plateau region
}
