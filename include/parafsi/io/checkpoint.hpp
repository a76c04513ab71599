/// \file checkpoint.hpp
/// Checkpoint/restart of the full state of fluid solvers, structure assemblies and
/// coupled steppers, for the user's loop (DESIGN §1; io/ is never included by physics
/// headers). A run restored from a checkpoint continues bit for bit like the run that
/// wrote it (tests/test_io_checkpoint.cpp), on the same build and thread-independent
/// kernels.
///
///   io::save_checkpoint("out/run.ckpt", stepper, scene);      // or (solver, assembly, ...)
///   ...
///   explicit_stepper s2{same scene};  io::scene_signature scene2{same parameters};
///   io::load_checkpoint("out/run.ckpt", s2, scene2);          // then continue stepping
///
/// Arguments are fluid solvers, structure assemblies, explicit_steppers, at most one
/// io::scene_signature and components that name their own section (a static
/// `checkpoint_section`, e.g. io::drop_history_record: section "history").
/// The k-th solver goes to the section "fluid" (k = 0) or "fluid.k", the k-th assembly
/// to "structure"/"structure.k"; a stepper writes its fluid and its structure there and
/// its own clock and coupling to "stepper"; a scene signature to "scene". Loading reads the sections its arguments need
/// and ignores the others (a stepper's fluid and assembly may also be loaded on their own, and a stepper built from
/// them afterwards: its clock then starts at the fluid's time and its first coupling kick uses its first substep).
///
/// What is stored is what each component's `serialize` says (io/archive.hpp explains the
/// archive; every entry is named, fields by their SoA tag names):
///   fluid::solver      signature (policy names, ghosts, grid faces, cell count, field
///                      length, gas); time, step count, pose X R V Ω, the frame policy
///                      (frame::translate / rigid / follow_payload serialize their own
///                      state; frame::fixed holds none), conserved fields "conserved.rho"
///                      … "conserved.E" (ghosts and SIMD padding included), the sources
///                      "sources.s_mx" … "sources.s_rho" if enabled, "turbulence.mu_t" and
///                      "turbulence.wall_distance" when the closure keeps them.
///   structure::assembly signature (type, node count, part names and element counts);
///                      constraint kinds and point masses (structure::nodes); a digest
///                      of each element part's connectivity, rest lengths and reference
///                      areas (compared: the scene is rebuilt by the user); node arrays
///                      "node.x" … "node.fez"; each part's state (membrane_tri /
///                      membrane_quad: per-element pressure; attachment → rigid_body:
///                      every field of rigid_body_state); integrator settings; clock and
///                      energy ledger.
///   explicit_stepper   coupling type (compared), time, steps, last substep count, last
///                      substep length; its coupling: penalty (porosity law and options
///                      compared; every point's penetration, the cumulative coupling
///                      energy) or embedded (set-up compared; no state carries over).
///   io::scene_signature user-named parameters of the scene (see below), compared.
///
/// Errors are `checkpoint_error` (an invalid_input) naming the file, the section and
/// what differs, e.g. "grid axis 0 has 16 cells in the file but 24 in this solver".
/// An unreadable, truncated, corrupted or foreign file, or one of another format
/// version, is refused before anything is changed. Each section's signature is checked
/// before its state is read; a difference found later (an entry of another name, a
/// non-finite value) leaves that object partly restored, so rebuild it before retrying.
/// Version 1 files (entries by position) are refused naming the version: restart from
/// a checkpoint written by the same build.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "../core/error.hpp"
#include "archive.hpp"

namespace parafsi::io {

/// The parameters that made a scene (canopy, fabric, resolution, α, payload mass,
/// moduli, line stiffness …), named by the program that builds it. Saved with a
/// checkpoint and compared on load: a restart whose scene differs is refused naming the
/// parameter and both values ("scene parameter 'payload_mass' is 100 in the file but 50
/// here"), or the parameter missing on one side. Doubles compare bit for bit.
///
///   io::scene_signature scene;
///   scene.add("pgs_alpha", c.alpha).add("payload_mass", c.payload_mass).add("fabric", c.fabric);
///   io::save_checkpoint(path, stepper, scene);   ...   io::load_checkpoint(path, stepper, scene);
class scene_signature {
 public:
  using value = std::variant<double, std::int64_t, std::string>;

  scene_signature& add(std::string name, double v) { return put(std::move(name), value(v)); }
  scene_signature& add(std::string name, std::string v) { return put(std::move(name), value(std::move(v))); }
  scene_signature& add(std::string name, const char* v) { return put(std::move(name), value(std::string(v))); }
  template <class I>
  requires(std::is_integral_v<I> && !std::is_same_v<I, bool>) scene_signature& add(std::string name, I v) {
    return put(std::move(name), value(std::int64_t(v)));
  }
  scene_signature& add(std::string name, bool v) {
    return put(std::move(name), value(std::string(v ? "true" : "false")));
  }

  const std::vector<std::pair<std::string, value>>& entries() const noexcept { return entries_; }

  /// Checkpoint: the parameter names, then each value, all compared on load.
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    std::string names;
    for (const auto& [n, v] : self.entries_) names += n + "\n";
    ar.check("parameters", names, [](const std::string& file, const std::string& here) -> std::string {
      if (file == here) return {};
      const auto f = split(file), h = split(here);
      for (const auto& n : f)
        if (std::find(h.begin(), h.end(), n) == h.end())
          return "scene parameter '" + n + "' is in the file but not in this run's scene signature";
      for (const auto& n : h)
        if (std::find(f.begin(), f.end(), n) == f.end())
          return "scene parameter '" + n + "' is in this run's scene signature but not in the file";
      return "the scene parameters are in another order in the file";
    });
    for (const auto& [n, v] : self.entries_)
      std::visit([&](const auto& x) { ar.check(n, x, "scene parameter '" + n + "'"); }, v);
  }

 private:
  scene_signature& put(std::string name, value v) {
    require(!name.empty() && name.find('\n') == std::string::npos && name != "parameters",
            "io::scene_signature::add: bad parameter name '", name, "'");
    for (const auto& [n, x] : entries_)
      require(n != name, "io::scene_signature::add: parameter '", name, "' given twice");
    if (const auto* d = std::get_if<double>(&v))
      require(std::isfinite(*d), "io::scene_signature::add: parameter '", name, "' is not finite (", *d, ")");
    entries_.emplace_back(std::move(name), std::move(v));
    return *this;
  }
  static std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    std::size_t a = 0;
    for (std::size_t b = s.find('\n'); b != std::string::npos; a = b + 1, b = s.find('\n', a))
      out.push_back(s.substr(a, b - a));
    return out;
  }
  std::vector<std::pair<std::string, value>> entries_;
};

namespace ckpt {

template <class T>
concept fluid_solver = requires(const T& s) {
  s.grid();
  s.pose();
  s.conserved_storage();
  s.frame();
  T::has_eddy_viscosity;
};
template <class T>
concept structure_assembly = requires(const T& a) {
  a.node_set();
  a.previous_step();
  T::part_count;
};
template <class T>
concept coupled_stepper = requires(const T& s) {
  T::has_fluid;
  T::has_structure;
  s.last_substeps();
};

/// A component that names its own section (`static constexpr const char* checkpoint_section`),
/// e.g. io::drop_history_record: the program's records beside the physical state.
template <class T>
concept named_section = requires {
  T::checkpoint_section;
};

inline std::string fluid_section(int k) { return k == 0 ? std::string("fluid") : "fluid." + std::to_string(k); }
inline std::string structure_section(int k) {
  return k == 0 ? std::string("structure") : "structure." + std::to_string(k);
}

/// Visit every (section name, object) an argument list stands for, in file order.
template <class F, class... Parts>
void for_each_section(F&& f, Parts&... parts) {
  int nf = 0, ns = 0, nscene = 0;
  auto one = [&](auto& p) {
    using P = std::remove_cvref_t<decltype(p)>;
    if constexpr (coupled_stepper<P>) {
      if constexpr (P::has_fluid) f(fluid_section(nf++), p.fluid());
      if constexpr (P::has_structure) f(structure_section(ns++), p.structure());
      f(std::string("stepper"), p);
    } else if constexpr (fluid_solver<P>) {
      f(fluid_section(nf++), p);
    } else if constexpr (structure_assembly<P>) {
      f(structure_section(ns++), p);
    } else if constexpr (named_section<P>) {
      f(std::string(P::checkpoint_section), p);
    } else if constexpr (std::is_same_v<P, scene_signature>) {
      require(nscene++ == 0, "io::checkpoint: give at most one scene_signature");
      f(std::string("scene"), p);
    } else {
      static_assert(sizeof(P) == 0,
                    "io::checkpoint: argument is not a fluid solver, assembly, explicit_stepper or scene_signature");
    }
  };
  (one(parts), ...);
}

}  // namespace ckpt

// ================================================================== public API

/// Write every argument (fluid solvers, assemblies, explicit_steppers, a scene_signature)
/// to `path` (atomically: `<path>.tmp`, then a rename).
template <class... Parts>
void save_checkpoint(const std::filesystem::path& path, const Parts&... parts) {
  static_assert(sizeof...(Parts) > 0, "io::save_checkpoint: give at least one solver, assembly or stepper");
  output_archive ar;
  ckpt::for_each_section(
      [&](const std::string& section, const auto& obj) {
    ar.begin_section(section);
    std::remove_cvref_t<decltype(obj)>::serialize(ar, obj);
    ar.end_section(section);
      },
      parts...);
  write_checkpoint_file(path, ar);
}

/// Restore every argument (built like the run that wrote the file) from `path`; a
/// scene_signature is compared. Throws checkpoint_error naming the file, the section
/// and what differs.
template <class... Parts>
void load_checkpoint(const std::filesystem::path& path, Parts&... parts) {
  static_assert(sizeof...(Parts) > 0, "io::load_checkpoint: give at least one solver, assembly or stepper");
  const checkpoint_file file(path);
  ckpt::for_each_section(
      [&](const std::string& section, auto& obj) {
    input_archive ar = file.section(section);
    std::remove_cvref_t<decltype(obj)>::serialize(ar, obj);
    ar.finish();
      },
      parts...);
}

/// What a checkpoint holds, without restoring anything.
struct checkpoint_info {
  std::vector<std::string> sections;
  double time = 0;        ///< the stepper's, else the fluid's, else the structure's time
  long fluid_steps = -1;  ///< fluid::solver::steps() when written (-1: no fluid)
  long steps = -1;        ///< the stepper's steps (-1: no stepper section)
};
/// Reads the entries "time" and "steps" that the components' serialize write.
inline checkpoint_info read_checkpoint_info(const std::filesystem::path& path) {
  const checkpoint_file file(path);
  checkpoint_info info;
  info.sections = file.names();
  auto real = [&](const std::string& section, const char* name) {
    const auto v = file.section(section).find_real(name);
    if (!v) file.fail("section '", section, "' has no entry '", name, "'");
    return *v;
  };
  auto integer = [&](const std::string& section, const char* name) {
    const auto v = file.section(section).find_int(name);
    if (!v) file.fail("section '", section, "' has no entry '", name, "'");
    return long(*v);
  };
  if (file.has("structure")) info.time = real("structure", "time");
  if (file.has("fluid")) {
    info.time = real("fluid", "time");
    info.fluid_steps = integer("fluid", "steps");
  }
  if (file.has("stepper")) {
    info.time = real("stepper", "time");
    info.steps = integer("stepper", "steps");
  }
  return info;
}

}  // namespace parafsi::io
