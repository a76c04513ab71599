/// \file vec3.hpp
/// A 3-vector on the value type V (double or a SIMD pack) for pointwise physics.
/// Scalar rigid-body algebra (rotations, frames) uses Eigen; this type exists so the
/// same flux code runs lane-parallel.
#pragma once
#include "simd.hpp"

namespace parafsi {

template <class V>
struct vec3 {
  V x, y, z;
  PARAFSI_INLINE vec3 operator+(const vec3& o) const noexcept { return {x + o.x, y + o.y, z + o.z}; }
  PARAFSI_INLINE vec3 operator-(const vec3& o) const noexcept { return {x - o.x, y - o.y, z - o.z}; }
  PARAFSI_INLINE vec3 operator*(const V& s) const noexcept { return {x * s, y * s, z * s}; }
  PARAFSI_INLINE vec3& operator+=(const vec3& o) noexcept {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
};

template <class V, class S>
PARAFSI_INLINE V dot(const vec3<V>& a, const vec3<S>& b) noexcept {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class V>
PARAFSI_INLINE vec3<V> cross(const vec3<V>& a, const vec3<V>& b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
/// a + s * n for a vector n of plain doubles (a face normal).
template <class V>
PARAFSI_INLINE vec3<V> axpy_n(const vec3<V>& a, const V& s, const vec3<double>& n) noexcept {
  return {a.x + s * n.x, a.y + s * n.y, a.z + s * n.z};
}

}  // namespace parafsi
