// Observers: VTK XML writers (structure .vtu, fluid .vts, block mesh .vtu, .pvd) and mid-plane slices.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <parafsi/fluid/fluid.hpp>
#include <parafsi/io/block_vtk.hpp>
#include <parafsi/io/vtk.hpp>
#include <parafsi/structure/structure.hpp>

namespace fs = std::filesystem;
using namespace parafsi;
namespace st = parafsi::structure;

namespace {
fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / "parafsi_test_io_vtk";
  fs::create_directories(d);
  return d / name;
}
std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// ---- a minimal XML reader: elements, attributes, text; throws on malformed input.
struct node {
  std::string name;
  std::map<std::string, std::string> attr;
  std::string text;
  std::vector<std::unique_ptr<node>> kids;
  const node* child(const std::string& n) const {
    for (const auto& k : kids)
      if (k->name == n) return k.get();
    return nullptr;
  }
  void find_all(const std::string& n, std::vector<const node*>& out) const {
    if (name == n) out.push_back(this);
    for (const auto& k : kids) k->find_all(n, out);
  }
  const node* array(const std::string& n) const {
    std::vector<const node*> all;
    find_all("DataArray", all);
    for (auto* a : all)
      if (a->attr.count("Name") && a->attr.at("Name") == n) return a;
    return nullptr;
  }
};
std::unique_ptr<node> parse_xml(const std::string& s) {
  std::size_t i = 0;
  auto fail = [&](const char* what) {
    throw std::runtime_error(std::string("xml: ") + what + " at " + std::to_string(i));
  };
  auto root = std::make_unique<node>();
  root->name = "#document";
  std::vector<node*> stack{root.get()};
  while (i < s.size()) {
    if (s[i] == '<') {
      if (s.compare(i, 2, "<?") == 0) {
        const auto e = s.find("?>", i);
        if (e == std::string::npos) fail("unterminated declaration");
        i = e + 2;
        continue;
      }
      if (s.compare(i, 2, "</") == 0) {
        const auto e = s.find('>', i);
        if (e == std::string::npos) fail("unterminated end tag");
        const std::string n = s.substr(i + 2, e - i - 2);
        if (stack.size() < 2 || stack.back()->name != n) fail("mismatched end tag");
        stack.pop_back();
        i = e + 1;
        continue;
      }
      auto el = std::make_unique<node>();
      ++i;
      while (i < s.size() && !std::isspace((unsigned char)s[i]) && s[i] != '>' && s[i] != '/') el->name += s[i++];
      if (el->name.empty()) fail("empty tag name");
      bool self = false;
      for (;;) {
        while (i < s.size() && std::isspace((unsigned char)s[i])) ++i;
        if (i >= s.size()) fail("unterminated tag");
        if (s[i] == '/') {
          self = true;
          if (s[i + 1] != '>') fail("bad />");
          i += 2;
          break;
        }
        if (s[i] == '>') {
          ++i;
          break;
        }
        std::string k;
        while (i < s.size() && s[i] != '=' && !std::isspace((unsigned char)s[i])) k += s[i++];
        if (s[i] != '=' || s[i + 1] != '"') fail("attribute without quoted value");
        const auto e = s.find('"', i + 2);
        if (e == std::string::npos) fail("unterminated attribute");
        if (el->attr.count(k)) fail("duplicate attribute");
        el->attr[k] = s.substr(i + 2, e - i - 2);
        i = e + 1;
      }
      node* raw = el.get();
      stack.back()->kids.push_back(std::move(el));
      if (!self) stack.push_back(raw);
    } else {
      const auto e = s.find('<', i);
      const std::string t = s.substr(i, (e == std::string::npos ? s.size() : e) - i);
      if (stack.size() == 1 && t.find_first_not_of(" \n\r\t") != std::string::npos) fail("text outside the root");
      stack.back()->text += t;
      i = e == std::string::npos ? s.size() : e;
    }
  }
  if (stack.size() != 1) fail("unclosed element");
  if (root->kids.size() != 1) fail("not exactly one root element");
  return root;
}

std::vector<unsigned char> unbase64(const std::string& in) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  std::vector<unsigned char> out;
  unsigned buf = 0;
  int bits = 0;
  for (char c : in) {
    const int v = val(c);
    if (v < 0) continue;
    buf = (buf << 6) | unsigned(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((buf >> bits) & 0xFF));
    }
  }
  return out;
}

/// Values of a DataArray as doubles (ascii or base64 binary with a UInt64 header).
std::vector<double> values(const node* a) {
  REQUIRE(a != nullptr);
  std::vector<double> v;
  const std::string type = a->attr.at("type");
  if (a->attr.at("format") == "ascii") {
    std::istringstream in(a->text);
    for (double x; in >> x;) v.push_back(x);
    return v;
  }
  const auto raw = unbase64(a->text);
  REQUIRE(raw.size() >= 8);
  std::uint64_t n;
  std::memcpy(&n, raw.data(), 8);
  REQUIRE(raw.size() == 8 + n);
  const unsigned char* p = raw.data() + 8;
  auto take = [&](auto tag) {
    using T = decltype(tag);
    for (std::size_t k = 0; k < n / sizeof(T); ++k) {
      T x;
      std::memcpy(&x, p + k * sizeof(T), sizeof(T));
      v.push_back(double(x));
    }
  };
  if (type == "Float64") take(double{});
  else if (type == "Int64") take(std::int64_t{});
  else if (type == "Int32") take(std::int32_t{});
  else if (type == "UInt8") take(std::uint8_t{});
  else FAIL("unknown type " << type);
  return v;
}

/// membrane (2 triangles) + cable + rigid body, finalized and one step taken.
auto small_assembly() {
  st::nodes nd;
  const index_t n0 = nd.add({0, 0, 1}), n1 = nd.add({1, 0, 1}), n2 = nd.add({1, 1, 1}), n3 = nd.add({0, 1, 1});
  const index_t hang = nd.add({0.5, 0.5, 0});
  st::triangle_mesh m;
  m.triangles = {{n0, n1, n2}, {n0, n2, n3}};
  m.reference = {{0, 0, 1}, {0.95, 0, 1}, {0.95, 0.95, 1}, {0, 0.95, 1}, {0.5, 0.5, 0}};  // pre-stretched
  st::attachment body{st::rigid_body{st::rigid_body::cuboid(2.0, {0.2, 0.2, 0.2}), {0.5, 0.5, -0.1}}};
  body.attach(hang, {0, 0, 0.1});
  st::assembly a{std::move(nd), st::membrane_tri{m, st::material::fabric<>::isotropic(1e8, 0.3, 0.05, 1e-4)},
                 st::cable{st::line_mesh{{{n0, hang}, {n2, hang}}, {1.1, 1.1}},
                           st::material::cable{1e4, 0.01, 0.05, 0}},
                 std::move(body)};
  a.finalize();
  return a;
}
}  // namespace

TEST_CASE("vtu: well-formed XML, point/cell counts, stresses and tensions round-trip (ascii and binary)") {
  auto a = small_assembly();
  a.step(a.stable_dt());
  for (auto enc : {io::vtk_encoding::ascii, io::vtk_encoding::binary}) {
    const fs::path p = scratch(enc == io::vtk_encoding::ascii ? "s_ascii.vtu" : "s_bin.vtu");
    io::vtu_options o;
    o.encoding = enc;
    o.cell_tags = {7, 7, 3, 3, 9};
    io::write_vtu(p, a, o);
    CHECK_FALSE(fs::exists(p.string() + ".tmp"));
    const auto doc = parse_xml(slurp(p));
    const node* f = doc->kids[0].get();
    CHECK(f->name == "VTKFile");
    CHECK(f->attr.at("type") == "UnstructuredGrid");
    const node* piece = f->child("UnstructuredGrid")->child("Piece");
    REQUIRE(piece);
    CHECK(piece->attr.at("NumberOfPoints") == "6");  // 5 nodes + 1 body point
    CHECK(piece->attr.at("NumberOfCells") == "5");   // 2 triangles + 2 lines + 1 vertex
    const auto types = values(piece->array("types"));
    CHECK(types == std::vector<double>{5, 5, 3, 3, 1});
    CHECK(values(piece->array("offsets")) == std::vector<double>{3, 6, 8, 10, 11});
    CHECK(values(piece->array("connectivity")) == std::vector<double>{0, 1, 2, 0, 2, 3, 0, 4, 2, 4, 5});
    CHECK(values(piece->array("part")) == std::vector<double>{0, 0, 1, 1, 2});
    CHECK(values(piece->array("tag")) == std::vector<double>{7, 7, 3, 3, 9});
    const auto pts = values(piece->child("Points")->child("DataArray"));
    REQUIRE(pts.size() == 18);
    for (index_t i = 0; i < 5; ++i)
      for (int d = 0; d < 3; ++d) CHECK(pts[std::size_t(3 * i + d)] == a.node_set().position(i)[d]);
    const auto vel = values(piece->array("velocity"));
    for (index_t i = 0; i < 5; ++i)
      for (int d = 0; d < 3; ++d) CHECK(vel[std::size_t(3 * i + d)] == a.node_set().velocity(i)[d]);
    const auto S = values(piece->array("stress")), E = values(piece->array("strain"));
    const auto vm = values(piece->array("effective_stress")), T = values(piece->array("tension"));
    for (index_t e = 0; e < 2; ++e) {
      const auto ss = a.part<0>().strain_stress(a.node_set(), e);
      CHECK(ss[3] != 0.0);
      for (int q = 0; q < 3; ++q) {
        CHECK(E[std::size_t(3 * e + q)] == ss[std::size_t(q)]);
        CHECK(S[std::size_t(3 * e + q)] == ss[std::size_t(3 + q)]);
      }
      CHECK(vm[std::size_t(e)] ==
            doctest::Approx(std::sqrt(ss[3] * ss[3] - ss[3] * ss[4] + ss[4] * ss[4] + 3 * ss[5] * ss[5])));
      CHECK(T[std::size_t(e)] == 0.0);
    }
    for (index_t e = 0; e < 2; ++e) {
      CHECK(T[std::size_t(2 + e)] == a.part<1>().tension(a.node_set(), e));
      CHECK(T[std::size_t(2 + e)] > 0);
    }
    CHECK(values(f->child("UnstructuredGrid")->child("FieldData")->child("DataArray")) ==
          std::vector<double>{a.time()});
  }
  io::vtu_options bad;
  bad.cell_tags = {1, 2};
  CHECK_THROWS_WITH_AS(io::write_vtu(scratch("bad.vtu"), a, bad), doctest::Contains("2 cell tags for 5 cells"),
                       invalid_input);
}

// A VTK file that cannot be written is an error naming the file and the system's reason:
// the temporary file linked to /dev/full (every write fails with ENOSPC).
TEST_CASE("vtu: a failed write throws io::write_error naming the file") {
  if (!fs::exists("/dev/full")) return;
  auto a = small_assembly();
  const fs::path p = scratch("full.vtu");
  fs::path tmp = p;
  tmp += ".tmp";
  fs::remove(tmp);
  fs::create_symlink("/dev/full", tmp);
  CHECK_THROWS_WITH_AS(io::write_vtu(p, a), doctest::Contains("full.vtu.tmp': No space left on device"),
                       io::write_error);
  fs::remove(tmp);
  CHECK_FALSE(fs::exists(p));
}

TEST_CASE(
    "vts: inertial corner points on a turned box, cell values round-trip, vorticity of solid rotation = 2 Omega") {
  const auto grid = fluid::rectilinear_grid(fluid::axis::refined(-1.0, 1.0, -0.3, 0.3, 0.1, 1.2),
                                            fluid::axis::uniform(6, -0.6, 0.6), fluid::axis::uniform(5, 0.0, 1.0));
  fluid::solver s{grid, boundary::set::all(boundary::far_field{})};
  s.pose().X = {10.0, -2.0, 3.0};
  s.pose().R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d Omega(0.3, -1.2, 2.0), centre(9.0, -1.0, 3.5);
  for (index_t k = 0; k < grid.n(2); ++k)
    for (index_t j = 0; j < grid.n(1); ++j)
      for (index_t i = 0; i < grid.n(0); ++i) {
        const Eigen::Vector3d x = s.pose().to_inertial({grid.centre(0, i), grid.centre(1, j), grid.centre(2, k)});
        const Eigen::Vector3d u = Omega.cross(x - centre);
        s.set_primitive(i, j, k, {1.0 + 0.01 * double(i + 3 * j + 7 * k), {u.x(), u.y(), u.z()}, 1e5 + double(i)});
      }
  const auto w = io::vorticity(s);
  for (std::size_t c = 0; c < w.size() / 3; ++c)
    for (int d = 0; d < 3; ++d) CHECK(w[3 * c + std::size_t(d)] == doctest::Approx(2 * Omega[d]).epsilon(1e-11));

  for (auto enc : {io::vtk_encoding::ascii, io::vtk_encoding::binary}) {
    const fs::path p = scratch(enc == io::vtk_encoding::ascii ? "f_ascii.vts" : "f_bin.vts");
    io::write_vts(p, s, {enc});
    const auto doc = parse_xml(slurp(p));
    const node* sg = doc->kids[0]->child("StructuredGrid");
    REQUIRE(sg);
    const index_t nx = grid.n(0), ny = grid.n(1), nz = grid.n(2);
    const std::string ext = "0 " + std::to_string(nx) + " 0 " + std::to_string(ny) + " 0 " + std::to_string(nz);
    CHECK(sg->attr.at("WholeExtent") == ext);
    const node* piece = sg->child("Piece");
    const auto pts = values(piece->child("Points")->child("DataArray"));
    REQUIRE(pts.size() == std::size_t(3 * (nx + 1) * (ny + 1) * (nz + 1)));
    // Corner (i, j, k) = (nx, 2, 1).
    const std::size_t q = std::size_t(nx + (nx + 1) * (2 + (ny + 1) * 1));
    const Eigen::Vector3d xq = s.pose().to_inertial({grid.face(0, nx), grid.face(1, 2), grid.face(2, 1)});
    for (int d = 0; d < 3; ++d) CHECK(pts[3 * q + std::size_t(d)] == xq[d]);
    const auto rho = values(piece->array("density")), vel = values(piece->array("velocity"));
    const auto pr = values(piece->array("pressure")), vo = values(piece->array("vorticity"));
    REQUIRE(rho.size() == std::size_t(nx * ny * nz));
    CHECK(vo.size() == 3 * rho.size());
    CHECK(piece->array("eddy_viscosity") == nullptr);
    for (index_t k = 0; k < nz; ++k)
      for (index_t j = 0; j < ny; ++j)
        for (index_t i = 0; i < nx; ++i) {
          const std::size_t c = std::size_t(i + nx * (j + ny * k));
          const auto wp = s.primitive(i, j, k);
          CHECK(rho[c] == wp.rho);
          CHECK(pr[c] == wp.p);
          CHECK(vel[3 * c] == wp.u.x);
          CHECK(vel[3 * c + 2] == wp.u.z);
          CHECK(vo[3 * c + 1] == w[3 * c + 1]);
        }
  }

  // Mid-plane: normal box y, through ξ_y = 0 (between layers 2 and 3).
  const fs::path mp = scratch("mid.csv");
  const std::size_t rows = io::write_midplane_csv(mp, s);
  CHECK(rows == std::size_t(grid.n(0) * grid.n(2)));
  std::ifstream in(mp);
  std::string line;
  std::getline(in, line);
  CHECK(line == "x,y,z,rho,u,v,w,p,vorticity_normal");
  std::size_t count = 0;
  const Eigen::Vector3d ny = s.pose().R.col(1);
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream ls(line);
    for (std::string cell; std::getline(ls, cell, ',');) v.push_back(std::stod(cell));
    REQUIRE(v.size() == 9);
    const Eigen::Vector3d x(v[0], v[1], v[2]);
    CHECK(s.pose().to_box(x)[1] == doctest::Approx(0.0).scale(1.0));  // on the plane
    const Eigen::Vector3d u = Omega.cross(x - centre);
    CHECK(v[4] == doctest::Approx(u.x()).epsilon(1e-8));  // linear field: interpolation exact
    CHECK(v[6] == doctest::Approx(u.z()).epsilon(1e-8));
    CHECK(v[8] == doctest::Approx(2 * Omega.dot(ny)).epsilon(1e-8));
    ++count;
  }
  CHECK(count == rows);
  CHECK_THROWS_AS(io::write_midplane_csv(mp, s, {3}), invalid_input);
  CHECK_THROWS_AS(io::write_midplane_csv(mp, s, {1, 5.0}), invalid_input);
}

TEST_CASE("vts: eddy viscosity is written when the solver has a closure") {
  fluid::solver s{fluid::rectilinear_grid::uniform({4, 3, 2}, {0, 0, 0}, {1, 1, 1}),
                  boundary::set::all(boundary::far_field{}), turbulence::smagorinsky{}, viscosity::constant{}};
  const fs::path p = scratch("t.vts");
  io::write_vts(p, s, {io::vtk_encoding::ascii});
  const auto doc = parse_xml(slurp(p));
  CHECK(values(doc->kids[0]->child("StructuredGrid")->child("Piece")->array("eddy_viscosity")).size() == 24);
}

namespace {
/// Signed volume of a VTK hexahedron (points 0–3 the lower face counter-clockwise seen from
/// above, 4–7 above them): six tetrahedra around the diagonal 0–6.
double hex_volume(const std::array<Eigen::Vector3d, 8>& p) {
  auto tet = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                const Eigen::Vector3d& d) { return (b - a).dot((c - a).cross(d - a)) / 6.0; };
  return tet(p[0], p[1], p[2], p[6]) + tet(p[0], p[2], p[3], p[6]) + tet(p[0], p[3], p[7], p[6]) +
         tet(p[0], p[7], p[4], p[6]) + tet(p[0], p[4], p[5], p[6]) + tet(p[0], p[5], p[1], p[6]);
}

/// A 2×2×2-block box on a turned pose with the block at (0, 1, 0) refined once (two
/// levels), filled with a solid rotation u = Ω × (x − x0), a density linear in box y and a
/// pressure varying along box x.
struct two_level_mesh {
  static constexpr index_t n = 4;
  const Eigen::Vector3d Omega{0.3, -1.2, 2.0}, centre{9.0, -1.0, 3.5};
  fluid::block_solver<> s{[] {
    fluid::blocks::tree t({2, 2, 2});
    t.refine(fluid::blocks::location{0, {0, 1, 0}});
    return t;
                          }(),
                          fluid::block_layout{{-1.0, -0.6, 0.0}, {1.0, 0.6, 1.0}, {2, 2, 2}, n},
                          boundary::set::all(boundary::far_field{})};
  two_level_mesh() {
    s.pose().X = {10.0, -2.0, 3.0};
    s.pose().R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    s.set_time(0.125);
    s.initialize([&](const Eigen::Vector3d& xi) {
      const Eigen::Vector3d u = Omega.cross(s.pose().to_inertial(xi) - centre);
      return fluid::prim<double>{1.2 + 0.1 * xi.y(), {u.x(), u.y(), u.z()}, 1e5 + 100.0 * xi.x()};
    });
  }
};
}  // namespace

TEST_CASE(
    "block vtu: one hexahedron per leaf cell, shared corners, volumes sum to the box, values round-trip, vorticity "
    "2 Omega across levels") {
  two_level_mesh m;
  const auto& s = m.s;
  REQUIRE(s.tree().finest_level() == 1);
  REQUIRE(s.block_count() == 15);  // 7 root blocks + 8 children
  const auto w = io::vorticity(s);
  REQUIRE(w.size() == 3 * std::size_t(s.cell_count()));
  for (std::size_t c = 0; c < w.size() / 3; ++c)
    for (int d = 0; d < 3; ++d) CHECK(w[3 * c + std::size_t(d)] == doctest::Approx(2 * m.Omega[d]).epsilon(1e-11));
  const double box_volume = 2.0 * 1.2 * 1.0;
  for (auto enc : {io::vtk_encoding::ascii, io::vtk_encoding::binary}) {
    const fs::path p = scratch(enc == io::vtk_encoding::ascii ? "b_ascii.vtu" : "b_bin.vtu");
    io::write_vtu(p, s, {enc, 250.0});
    CHECK_FALSE(fs::exists(p.string() + ".tmp"));
    const auto doc = parse_xml(slurp(p));
    const node* ug = doc->kids[0]->child("UnstructuredGrid");
    REQUIRE(ug);
    CHECK(values(ug->child("FieldData")->child("DataArray")) == std::vector<double>{0.125});
    const node* piece = ug->child("Piece");
    const std::size_t cells = std::size_t(s.cell_count());
    CHECK(std::stoul(piece->attr.at("NumberOfCells")) == cells);
    const auto pts = values(piece->child("Points")->child("DataArray"));
    const auto conn = values(piece->array("connectivity")), offs = values(piece->array("offsets"));
    const auto types = values(piece->array("types"));
    REQUIRE(std::stoul(piece->attr.at("NumberOfPoints")) * 3 == pts.size());
    REQUIRE(conn.size() == 8 * cells);
    REQUIRE(offs.size() == cells);
    CHECK(std::count(types.begin(), types.end(), 12.0) == std::ptrdiff_t(cells));
    // Corners written once: no two points coincide. Unique corners of the leaves: the
    // root lattice (2·4+1)³ plus the refined block's lattice (9³) less its 5³ coarse ones.
    std::vector<std::array<double, 3>> sorted;
    for (std::size_t q = 0; q < pts.size(); q += 3) sorted.push_back({pts[q], pts[q + 1], pts[q + 2]});
    std::sort(sorted.begin(), sorted.end());
    CHECK(std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end());
    CHECK(sorted.size() == std::size_t(9 * 9 * 9 + 9 * 9 * 9 - 5 * 5 * 5));
    const auto rho = values(piece->array("density")), vel = values(piece->array("velocity"));
    const auto pr = values(piece->array("pressure")), vo = values(piece->array("vorticity"));
    const auto lev = values(piece->array("level")), blk = values(piece->array("block"));
    REQUIRE(rho.size() == cells);
    REQUIRE(vo.size() == 3 * cells);
    double volume = 0, min_ratio = 1e300, max_ratio = 0;
    std::size_t mismatches = 0, fine = 0;
    for (std::size_t c = 0; c < cells; ++c) {
      CHECK(offs[c] == double(8 * (c + 1)));
      std::array<Eigen::Vector3d, 8> corner;
      Eigen::Vector3d mid = Eigen::Vector3d::Zero();
      for (int v = 0; v < 8; ++v) {
        const std::size_t q = std::size_t(conn[8 * c + std::size_t(v)]);
        corner[std::size_t(v)] = {pts[3 * q], pts[3 * q + 1], pts[3 * q + 2]};
        mid += corner[std::size_t(v)] / 8.0;
      }
      const double vol = hex_volume(corner);
      volume += vol;
      // The cell the written corners enclose holds the written values and is the written block.
      const Eigen::Vector3d xi = s.pose().to_box(mid);
      const auto [id, cell] = s.locate(xi);
      const auto& g = s.block_at(id).grid;
      const auto ijk = g.ijk(cell);
      const double ratio = vol / g.cell_volume(ijk[0], ijk[1], ijk[2]);
      min_ratio = std::min(min_ratio, ratio);
      max_ratio = std::max(max_ratio, ratio);
      const auto wp = s.sample(xi);
      const bool same = blk[c] == double(id) && lev[c] == double(s.block_at(id).where.level) && rho[c] == wp.rho &&
                        pr[c] == wp.p + 250.0 && vel[3 * c] == wp.u.x && vel[3 * c + 1] == wp.u.y &&
                        vel[3 * c + 2] == wp.u.z && vo[3 * c + 2] == w[3 * c + 2];
      mismatches += same ? 0 : 1;
      fine += lev[c] == 1.0 ? 1 : 0;
    }
    MESSAGE("block vtu: ", cells, " cells (", fine, " on level 1), ", sorted.size(), " points, volume ", volume);
    CHECK(mismatches == 0);
    CHECK(fine == 8 * 64);
    CHECK(volume == doctest::Approx(box_volume).epsilon(1e-12));
    CHECK(min_ratio == doctest::Approx(1.0).epsilon(1e-12));  // every hexahedron right-handed, its cell's volume
    CHECK(max_ratio == doctest::Approx(1.0).epsilon(1e-12));
  }
}

TEST_CASE(
    "block vtu pieces: the .pvtu index names every piece and array; the pieces' cells, in piece order, are the whole "
    "file's cells value for value") {
  two_level_mesh m;
  const auto& s = m.s;
  const io::vtk_options opt{io::vtk_encoding::ascii, 250.0};
  const fs::path whole = scratch("pieces_whole.vtu");
  io::write_vtu(whole, s, opt);
  const auto wdoc = parse_xml(slurp(whole));
  const node* wp = wdoc->kids[0]->child("UnstructuredGrid")->child("Piece");
  const auto wpts = values(wp->child("Points")->child("DataArray")), wconn = values(wp->array("connectivity"));
  const std::vector<std::string> names{"density", "velocity", "pressure", "vorticity", "level", "block"};
  // The 8 corner coordinates of every cell, in cell order (points are renumbered per piece).
  auto corners = [](const std::vector<double>& pts, const std::vector<double>& conn) {
    std::vector<double> c;
    for (double q : conn)
      for (int d = 0; d < 3; ++d) c.push_back(pts[3 * std::size_t(q) + std::size_t(d)]);
    return c;
  };
  const std::vector<double> wcorners = corners(wpts, wconn);
  for (int pieces : {1, 2, 4, 7, 15}) {
    const fs::path index = scratch("pieces_" + std::to_string(pieces) + ".pvtu");
    for (int q = pieces - 1; q >= 0; --q) io::write_pvtu_piece(index, s, opt, q, pieces);
    const auto doc = parse_xml(slurp(index));
    const node* pu = doc->kids[0]->child("PUnstructuredGrid");
    REQUIRE(pu);
    CHECK(doc->kids[0]->attr.at("type") == "PUnstructuredGrid");
    std::vector<const node*> listed, arrays;
    pu->find_all("Piece", listed);
    pu->child("PCellData")->find_all("PDataArray", arrays);
    REQUIRE(listed.size() == std::size_t(pieces));
    REQUIRE(arrays.size() == names.size());
    std::map<std::string, std::vector<double>> joined;
    std::vector<double> jcorners;
    std::size_t cells = 0;
    for (int q = 0; q < pieces; ++q) {
      const std::string src = listed[std::size_t(q)]->attr.at("Source");
      CHECK(src == "pieces_" + std::to_string(pieces) + "_" + std::to_string(q) + ".vtu");
      const auto pdoc = parse_xml(slurp(index.parent_path() / src));
      const node* piece = pdoc->kids[0]->child("UnstructuredGrid")->child("Piece");
      const io::block_range r = io::piece_blocks(s.block_count(), q, pieces);
      const std::size_t pc = std::stoul(piece->attr.at("NumberOfCells"));
      CHECK(pc == std::size_t((r.last - r.first) * m.n * m.n * m.n));
      cells += pc;
      for (std::size_t a = 0; a < names.size(); ++a) {
        const node* arr = piece->array(names[a]);
        REQUIRE(arr);
        CHECK(arr->attr.at("type") == arrays[a]->attr.at("type"));
        CHECK(arrays[a]->attr.at("Name") == names[a]);
        const auto v = values(arr);
        joined[names[a]].insert(joined[names[a]].end(), v.begin(), v.end());
      }
      const auto c = corners(values(piece->child("Points")->child("DataArray")), values(piece->array("connectivity")));
      jcorners.insert(jcorners.end(), c.begin(), c.end());
    }
    CHECK(cells == std::size_t(s.cell_count()));
    std::size_t differing = 0;
    for (const auto& nm : names) differing += joined[nm] == values(wp->array(nm)) ? 0 : 1;
    CHECK(differing == 0);
    CHECK(jcorners == wcorners);
    MESSAGE("block vtu pieces: ", pieces, " pieces, ", cells, " cells, ", differing, " arrays differing");
  }
  CHECK_THROWS_WITH_AS(io::write_pvtu_piece(scratch("pieces.vtu"), s, opt, 0, 2),
                       doctest::Contains("must be a .pvtu file"), invalid_input);
  CHECK_THROWS_WITH_AS(io::write_pvtu_piece(scratch("pieces.pvtu"), s, opt, 2, 2), doctest::Contains("piece 2 of 2"),
                       invalid_input);
}

TEST_CASE("block mid-plane CSV: one row per cut leaf cell, on the plane, exact for fields linear along the normal") {
  two_level_mesh m;
  const auto& s = m.s;
  const fs::path mp = scratch("block_mid.csv");
  // Normal box y through ξ_y = 0: the plane is the lower face of the upper blocks, one of
  // them refined, so rows come from 3 coarse blocks (n² cells each) and 4 fine ones.
  const std::size_t rows = io::write_midplane_csv(mp, s);
  CHECK(rows == std::size_t(7 * two_level_mesh::n * two_level_mesh::n));
  std::ifstream in(mp);
  std::string line;
  std::getline(in, line);
  CHECK(line == "x,y,z,rho,u,v,w,p,vorticity_normal");
  std::size_t count = 0;
  const Eigen::Vector3d ny = s.pose().R.col(1);
  double max_rho_err = 0, max_om_err = 0;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream ls(line);
    for (std::string cell; std::getline(ls, cell, ',');) v.push_back(std::stod(cell));
    REQUIRE(v.size() == 9);
    const Eigen::Vector3d xi = s.pose().to_box({v[0], v[1], v[2]});
    CHECK(xi[1] == doctest::Approx(0.0).scale(1.0));  // on the plane
    max_rho_err = std::max(max_rho_err, std::abs(v[3] - 1.2));
    max_om_err = std::max(max_om_err, std::abs(v[8] - 2 * m.Omega.dot(ny)));
    ++count;
  }
  MESSAGE("block mid-plane: ", rows, " rows, density error ", max_rho_err, ", normal vorticity error ", max_om_err);
  CHECK(count == rows);
  CHECK(max_rho_err < 1e-9);  // ρ = 1.2 + 0.1 ξ_y interpolated to ξ_y = 0 (10 digits written)
  CHECK(max_om_err < 1e-8);
  // An off-centre plane normal to box x at ξ_x = 0.3 cuts the fine block's layer too.
  CHECK(io::write_midplane_csv(mp, s, {0, -0.3}) == std::size_t(3 * 16 + 4 * 16));
  CHECK_THROWS_AS(io::write_midplane_csv(mp, s, {3}), invalid_input);
  CHECK_THROWS_WITH_AS(io::write_midplane_csv(mp, s, {1, 5.0}), doctest::Contains("outside the box"), invalid_input);
}

TEST_CASE("pvd: entries appended, collection always complete, resume keeps entries up to the restart time") {
  const fs::path p = scratch("series/run.pvd");
  {
    io::pvd_writer w(p);
    for (int i = 0; i < 4; ++i) w.add(0.1 * i, p.parent_path() / ("fluid_" + std::to_string(i) + ".vts"));
    w.add(0.3, "structure_3.vtu", 1);
    const auto doc = parse_xml(slurp(p));
    std::vector<const node*> ds;
    doc->find_all("DataSet", ds);
    REQUIRE(ds.size() == 5);
    CHECK(ds[2]->attr.at("file") == "fluid_2.vts");  // relative to the collection
    CHECK(ds[4]->attr.at("part") == "1");
    CHECK(std::stod(ds[1]->attr.at("timestep")) == 0.1);
  }
  io::pvd_writer r(p, 0.15);
  CHECK(r.size() == 2);
  r.add(0.2, p.parent_path() / "fluid_r.vts");
  const auto doc = parse_xml(slurp(p));
  std::vector<const node*> ds;
  doc->find_all("DataSet", ds);
  REQUIRE(ds.size() == 3);
  CHECK(ds[2]->attr.at("file") == "fluid_r.vts");
}
