/// \file patch.hpp
/// Face patches: the typed hook through which a coupling (coupling::embedded) replaces
/// the Riemann flux on chosen faces. A patcher P is given to the solver's step,
///   solver.step(dt, patcher)   or   solver.step(dt, motion, patcher),
/// and supplies
///   p.patch_faces()                 → the faces (high cell, axis), std::span<const patch_face>;
///   p.patch(fc, view, lo, hi)       → the fluxes through face fc (per unit area, ALE form):
///                                      `lo` what the low cell sends, `hi` what the high cell
///                                      receives (they may differ: a membrane in the face
///                                      takes the difference as its load).
/// The solver computes the regular flux first and corrects the two cells' rates, per RK
/// stage, in list order; the context names the stage and the patch index.
/// A patcher may split patch() into a pure half and a recording half
/// (recording_face_patcher):
///   p.solve_patch(fc, view, lo, hi) → double  (const: the fluxes, and one number for ...)
///   p.record_patch(fc, lo, hi, value)         (... the patcher's own sums; reads fc.patch,
///                                              fc.stage and fc.area only: the block mesh
///                                              sets no other field of fc here)
/// with patch() = record_patch(solve_patch()). The block mesh then solves the faces in
/// parallel (threads, and on a mesh split over processes each face on the process computing
/// its high cell, or on all where all compute it) and records them in list order on every
/// process, and each cell's rate is corrected in list order by the process computing it:
/// the same bits as patch() face by face. A patcher without the split is called
/// face by face in list order by every process. Either way, on a mesh split over processes
/// the view is current only at each face's two cells (fc.low, fc.high): a patcher must read
/// nothing else of the air.
#pragma once
#include <concepts>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../core/config.hpp"
#include "../core/vec3.hpp"
#include "state.hpp"
#include "view.hpp"

namespace parafsi::fluid {

/// A patched face: the face between cells high − stride(axis) and high.
struct patch_face {
  index_t high = 0;
  int axis = 0;
};

/// One patched face at one RK stage.
struct face_context {
  index_t low = 0, high = 0;  ///< flat indices, high = low + stride(axis)
  int axis = 0;
  int stage = 0;             ///< RK stage (0 … Time::stages − 1)
  std::size_t patch = 0;     ///< position of the face in the patcher's list
  prim<double> L{}, R{};     ///< reconstructed states on the low and high side
  vec3<double> n{};          ///< unit normal (inertial), from low to high
  double wn = 0;             ///< grid normal speed of the face
  double area = 0;           ///< face area (m²)
  Eigen::Vector3d centre{};  ///< face centre in box coordinates ξ
};

template <class P>
concept face_patcher = requires(P& p, const P& cp, const face_context& fc, const view& v, cons<double>& q) {
  { cp.patch_faces() } -> std::convertible_to<std::span<const patch_face>>;
  p.patch(fc, v, q, q);
};

/// A face patcher whose patch() is split into solve_patch (const) and record_patch.
template <class P>
concept recording_face_patcher = face_patcher<P> &&
    requires(P& p, const P& cp, const face_context& fc, const view& v, cons<double>& q) {
  { cp.solve_patch(fc, v, q, q) } -> std::convertible_to<double>;
  p.record_patch(fc, std::as_const(q), std::as_const(q), 0.0);
};

/// No patched faces.
struct no_patches {
  std::span<const patch_face> patch_faces() const noexcept { return {}; }
  void patch(const face_context&, const view&, cons<double>&, cons<double>&) noexcept {}
};

/// A fixed list of faces and a handler h(fc, lo, hi) or h(fc, view, lo, hi).
template <class Handler>
struct face_patches {
  std::vector<patch_face> faces;
  Handler handler;

  std::span<const patch_face> patch_faces() const noexcept { return faces; }
  void patch(const face_context& fc, const view& v, cons<double>& lo, cons<double>& hi) {
    if constexpr (std::invocable<Handler&, const face_context&, const view&, cons<double>&, cons<double>&>)
      handler(fc, v, lo, hi);
    else handler(fc, lo, hi);
  }
};
template <class Handler>
face_patches(std::vector<patch_face>, Handler) -> face_patches<Handler>;

}  // namespace parafsi::fluid
