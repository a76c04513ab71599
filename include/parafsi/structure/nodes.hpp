/// \file nodes.hpp
/// Structural nodes in SoA (position x, velocity v, force f, lumped mass m), shared by
/// every part of an assembly, and point constraints.
///
/// Each node is one of
///   - free:       integrated by the central-difference update, a = f/m;
///   - pinned:     x fixed, v = 0 (reaction = −f, does no work);
///   - prescribed: v fixed by the user, x advanced with it (reaction = −f, its work
///                 −f·v is counted as external work);
///   - attached:   placed from a rigid body's pose, x = X + R r, v = V + ω×(R r); its force
///                 is handed to the body (see attachment.hpp). Never integrated itself.
/// Constrained nodes carry 1/m = 0, so the vectorized update needs no branch; the
/// constrained list is visited afterwards to restore exact positions and velocities.
///
/// Masses: user point masses (add(..., point_mass)) plus the lumped masses of the parts,
/// recomputed by assembly::finalize().
#pragma once
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/soa.hpp"

namespace parafsi::structure {

namespace field {
struct x {
  static constexpr const char* name = "x";
};
struct y {
  static constexpr const char* name = "y";
};
struct z {
  static constexpr const char* name = "z";
};
struct vx {
  static constexpr const char* name = "vx";
};
struct vy {
  static constexpr const char* name = "vy";
};
struct vz {
  static constexpr const char* name = "vz";
};
struct fx {
  static constexpr const char* name = "fx";
};
struct fy {
  static constexpr const char* name = "fy";
};
struct fz {
  static constexpr const char* name = "fz";
};
struct m {
  static constexpr const char* name = "m";
};
struct minv {
  static constexpr const char* name = "minv";
};
// Energy bookkeeping: damping and applied (external) parts of f, filled only when tracking.
struct fdx {
  static constexpr const char* name = "fdx";
};
struct fdy {
  static constexpr const char* name = "fdy";
};
struct fdz {
  static constexpr const char* name = "fdz";
};
struct fex {
  static constexpr const char* name = "fex";
};
struct fey {
  static constexpr const char* name = "fey";
};
struct fez {
  static constexpr const char* name = "fez";
};
}  // namespace field

using node_fields =
    meta::list<field::x, field::y, field::z, field::vx, field::vy, field::vz, field::fx, field::fy, field::fz, field::m,
               field::minv, field::fdx, field::fdy, field::fdz, field::fex, field::fey, field::fez>;

enum class constraint : unsigned char { free = 0, pinned = 1, prescribed = 2, attached = 3 };

/// Read-only positions and velocities, the view element kernels take.
struct node_kinematics {
  const double* x;
  const double* y;
  const double* z;
  const double* vx;
  const double* vy;
  const double* vz;
  index_t n;
};

class nodes {
 public:
  using storage = soa_of_t<node_fields>;

  nodes() = default;

  /// Append a node at x with velocity v and an optional point mass (kg). Returns its id.
  index_t add(const Eigen::Vector3d& x, const Eigen::Vector3d& v = Eigen::Vector3d::Zero(), double point_mass = 0.0) {
    require(x.allFinite() && v.allFinite(), "structure::nodes::add: non-finite position or velocity for node ", size());
    require(point_mass >= 0.0, "structure::nodes::add: point mass must be >= 0, got ", point_mass);
    if (!dirty_pos_) sync_back();
    px_.push_back(x);
    pv_.push_back(v);
    point_mass_.push_back(point_mass);
    kind_.push_back(constraint::free);
    dirty_ = true;
    return index_t(px_.size()) - 1;
  }
  index_t size() const noexcept { return index_t(kind_.size()); }

  // ------------------------------------------------------------- constraints
  void pin(index_t i) {
    check(i, "pin");
    kind_[std::size_t(i)] = constraint::pinned;
    set_velocity(i, Eigen::Vector3d::Zero());
    dirty_ = true;
  }
  void prescribe_velocity(index_t i, const Eigen::Vector3d& v) {
    check(i, "prescribe_velocity");
    require(v.allFinite(), "structure::nodes::prescribe_velocity: non-finite velocity for node ", i);
    kind_[std::size_t(i)] = constraint::prescribed;
    set_velocity(i, v);
    dirty_ = true;
  }
  void release(index_t i) {
    check(i, "release");
    kind_[std::size_t(i)] = constraint::free;
    dirty_ = true;
  }
  /// Used by the rigid-body attachment; users attach through attachment::attach.
  void mark_attached(index_t i) {
    check(i, "mark_attached");
    kind_[std::size_t(i)] = constraint::attached;
    dirty_ = true;
  }
  constraint kind(index_t i) const { return kind_[std::size_t(i)]; }
  /// Ids of every non-free node, ascending.
  const std::vector<index_t>& constrained() const noexcept { return constrained_; }

  // ------------------------------------------------------------- masses
  double point_mass(index_t i) const { return point_mass_[std::size_t(i)]; }
  void set_point_mass(index_t i, double m) {
    check(i, "set_point_mass");
    require(m >= 0.0, "structure::nodes::set_point_mass: mass must be >= 0, got ", m, " at node ", i);
    point_mass_[std::size_t(i)] = m;
    dirty_ = true;
  }
  /// Reset m to the point masses (first step of assembly::finalize()).
  void reset_masses() {
    materialize();
    double* m = s_.get<field::m>();
    for (index_t i = 0; i < size(); ++i) m[i] = point_mass_[std::size_t(i)];
  }
  /// Add a lumped contribution (parts call this from assembly::finalize()).
  void add_mass(index_t i, double m) { s_.get<field::m>()[i] += m; }
  /// Compute 1/m (0 for constrained nodes) and the constrained list; a free node
  /// without mass is an error that names it.
  void finalize_masses() {
    materialize();
    double* m = s_.get<field::m>();
    double* mi = s_.get<field::minv>();
    constrained_.clear();
    for (index_t i = 0; i < size(); ++i) {
      const bool free = kind_[std::size_t(i)] == constraint::free;
      if (free)
        require(m[i] > 0.0 && std::isfinite(m[i]), "structure::nodes: free node ", i, " has mass ", m[i],
                " (attach it to an element, give it a point mass, or pin it)");
      mi[i] = free ? 1.0 / m[i] : 0.0;
      if (!free) constrained_.push_back(i);
    }
  }
  double mass(index_t i) const { return s_.get<field::m>()[i]; }

  // ------------------------------------------------------------- state access
  Eigen::Vector3d position(index_t i) const {
    if (dirty_pos_) return px_[std::size_t(i)];
    return {s_.get<field::x>()[i], s_.get<field::y>()[i], s_.get<field::z>()[i]};
  }
  Eigen::Vector3d velocity(index_t i) const {
    if (dirty_pos_) return pv_[std::size_t(i)];
    return {s_.get<field::vx>()[i], s_.get<field::vy>()[i], s_.get<field::vz>()[i]};
  }
  Eigen::Vector3d force(index_t i) const {
    return {s_.get<field::fx>()[i], s_.get<field::fy>()[i], s_.get<field::fz>()[i]};
  }
  void set_position(index_t i, const Eigen::Vector3d& x) {
    check(i, "set_position");
    require(x.allFinite(), "structure::nodes::set_position: non-finite position for node ", i);
    if (dirty_pos_) {
      px_[std::size_t(i)] = x;
      return;
    }
    s_.get<field::x>()[i] = x.x();
    s_.get<field::y>()[i] = x.y();
    s_.get<field::z>()[i] = x.z();
  }
  void set_velocity(index_t i, const Eigen::Vector3d& v) {
    check(i, "set_velocity");
    require(v.allFinite(), "structure::nodes::set_velocity: non-finite velocity for node ", i);
    if (dirty_pos_) {
      pv_[std::size_t(i)] = v;
      return;
    }
    s_.get<field::vx>()[i] = v.x();
    s_.get<field::vy>()[i] = v.y();
    s_.get<field::vz>()[i] = v.z();
  }

  /// Move the staging arrays of add() into the SoA (idempotent; done by finalize).
  void materialize() {
    if (!dirty_pos_) return;
    s_.resize(size(), 0.0);
    for (index_t i = 0; i < size(); ++i) {
      s_.get<field::x>()[i] = px_[std::size_t(i)].x();
      s_.get<field::y>()[i] = px_[std::size_t(i)].y();
      s_.get<field::z>()[i] = px_[std::size_t(i)].z();
      s_.get<field::vx>()[i] = pv_[std::size_t(i)].x();
      s_.get<field::vy>()[i] = pv_[std::size_t(i)].y();
      s_.get<field::vz>()[i] = pv_[std::size_t(i)].z();
    }
    dirty_pos_ = false;
  }
  bool needs_finalize() const noexcept { return dirty_ || dirty_pos_; }
  void mark_finalized() noexcept { dirty_ = false; }

  node_kinematics kinematics() const noexcept {
    return {s_.get<field::x>(),
            s_.get<field::y>(),
            s_.get<field::z>(),
            s_.get<field::vx>(),
            s_.get<field::vy>(),
            s_.get<field::vz>(),
            size()};
  }
  storage& data() noexcept { return s_; }
  const storage& data() const noexcept { return s_; }

  /// Checkpoint (io/archive.hpp): the constraint kinds and point masses, which may change
  /// during a run. A change on load marks the set for finalize; the node arrays follow
  /// (assembly::serialize writes them by tag name after the masses are final).
  template <class Archive, class Self>
  static void serialize(Archive& ar, Self& self) {
    std::vector<constraint> kind = self.kind_;
    std::vector<double> point_mass = self.point_mass_;
    ar("constraints", kind);
    ar("point_masses", point_mass);
    if constexpr (Archive::loading) {
      for (std::size_t i = 0; i < kind.size(); ++i) {
        if (unsigned(kind[i]) > unsigned(constraint::attached))
          ar.fail("node ", i, " has an unknown constraint kind ", unsigned(kind[i]));
        if (!(point_mass[i] >= 0.0)) ar.fail("node ", i, " has a negative point mass ", point_mass[i]);
      }
      if (kind != self.kind_ || point_mass != self.point_mass_) {
        self.kind_ = std::move(kind);
        self.point_mass_ = std::move(point_mass);
        self.dirty_ = true;
      }
    }
  }

 private:
  void check(index_t i, const char* what) const {
    require(i >= 0 && i < size(), "structure::nodes::", what, ": node id ", i, " out of range [0, ", size(), ")");
  }
  void sync_back() {
    for (index_t i = 0; i < s_.size(); ++i) {
      px_[std::size_t(i)] = {s_.get<field::x>()[i], s_.get<field::y>()[i], s_.get<field::z>()[i]};
      pv_[std::size_t(i)] = {s_.get<field::vx>()[i], s_.get<field::vy>()[i], s_.get<field::vz>()[i]};
    }
    dirty_pos_ = true;
  }
  storage s_;
  std::vector<Eigen::Vector3d> px_, pv_;  // staging until materialize()
  std::vector<double> point_mass_;
  std::vector<constraint> kind_;
  std::vector<index_t> constrained_;
  bool dirty_ = true;
  bool dirty_pos_ = true;
};

}  // namespace parafsi::structure
