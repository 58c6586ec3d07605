// gjkd.hpp: a header-only C++17 wrapper of the gjkd C API (gjkd.h).
//
// gjkd::Client owns a gjkd_client* (RAII, movable, not copyable) and turns
// every failed call into a gjkd::Error carrying the gjkd_status, the
// gjkd_error_code (for GJKD_ERR_REJECTED, and for GJKD_ERR_INVALID_ARGUMENT
// when the fault has one) and the message. Batches take pointer + count,
// std::vector, or (C++20) std::span, and write into a gjkd::Distances the
// caller keeps and reuses, or (query_pairs(), the fastest) read PairQuery
// rows and write Result rows.
//
// Threads: a Client may be used from any thread, one call at a time (a
// call overlapping another thread's call on the same Client throws
// GJKD_ERR_BUSY), and destroyed on any thread. Under a ROS 2
// MultiThreadedExecutor, give each callback group that may run at once
// its own Client, or guard a shared one with a std::mutex.
//
// Units are the caller's (the server has none): lengths in whatever unit
// the shapes were given in, joint positions in radians (prismatic joints
// in the URDF's length unit). A Pose is a translation and a unit
// quaternion stored x, y, z, w; Eigen's Quaterniond(w, x, y, z)
// constructor takes w first (see quat(), and to_eigen() / from_eigen()
// with GJKD_WITH_EIGEN defined before this header is included).
//
// Objects outlive the Client that registered them: they stay on the
// server until removed, and a server with persistence (the default) keeps
// them across restarts. Remove them (remove(), remove_robot()), or set
// RegistrationOptions::remove_on_close to have them end with the Client.
//
// Robots and meshes (Robot, register_robot*, register_mesh*, set_joints*,
// path_joints) are declared under GJKD_ROBOTS, as in gjkd.h: present when
// the library was built with its `robots` feature (the default install),
// hidden by GJKD_NO_ROBOTS (a lean install's build flags).
//
//   gjkd::Client client("gjkd");
//   gjkd::Id box = client.register_box({1, 1, 1});
//   gjkd::Id ball = client.register_sphere(0.5, gjkd::at(3, 0, 0));
//   double d = client.distance(box, ball).distance;   // 1.5
#ifndef GJKD_HPP
#define GJKD_HPP

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#ifdef GJKD_WITH_EIGEN
#include <Eigen/Geometry>
#endif

#if __cplusplus >= 202002L && __has_include(<span>)
#include <span>
#define GJKD_HAS_SPAN 1
#endif

#include "gjkd.h"

namespace gjkd {

/// Object id.
using Id = gjkd_id;
/// Pose: translation, then unit quaternion [qx, qy, qz, qw].
using Pose = gjkd_pose;
/// Answer of one pair query.
using Answer = gjkd_answer;
/// Query options; start from default_options().
using Options = gjkd_query_options;
/// A row of Client::query_pairs(): a pair, and poses for this query only.
using PairQuery = gjkd_pair_query;
/// An answer row of Client::query_pairs() (`error` 0 when answered).
using Result = gjkd_result;
/// A distance gradient (GJKD_PAIR_GRADIENT rows, scene rows' `gradient`).
using Gradient = gjkd_gradient;
/// A convex shape (see sphere(), capsule(), box(), polytope()).
using Shape = gjkd_shape;
/// A piece of a compound: an offset and a convex shape.
using Piece = gjkd_piece;
/// Three doubles.
using Vec3 = std::array<double, 3>;
/// A row of a scene answer: a pair and its answer.
using SceneRow = gjkd_scene_row;
/// What a scene answer held besides its rows.
using SceneSummary = gjkd_scene_summary;
/// Scene query options; start from default_scene_options().
using SceneOptions = gjkd_scene_options;
#if defined(GJKD_ROBOTS)
/// What a mesh registration made: its pieces and their deviation.
using MeshInfo = gjkd_mesh_info;
#endif // GJKD_ROBOTS
/// How registrations treat names and the Client's end (see
/// Client::set_registration_options()).
using RegistrationOptions = gjkd_registration_options;
/// A unit quaternion, stored x, y, z, w (as Pose::rotation).
using Quat = std::array<double, 4>;

/// A failed call: what gjkd_status it returned, its gjkd_error_code (the
/// server's for GJKD_ERR_REJECTED; for GJKD_ERR_INVALID_ARGUMENT the code
/// the server gives the same fault, when it has one; GJKD_CODE_OK
/// otherwise, see gjkd_last_error_code()), and the message.
class Error : public std::runtime_error {
public:
    Error(gjkd_status status, uint32_t code, const std::string &message)
        : std::runtime_error(message), status_(status), code_(static_cast<gjkd_error_code>(code)) {}
    /// The call's status.
    gjkd_status status() const noexcept { return status_; }
    /// The fault's code (GJKD_CODE_OK when none applies).
    gjkd_error_code code() const noexcept { return code_; }

private:
    gjkd_status status_;
    gjkd_error_code code_;
};

/// Throws the thread's last error if `status` is not GJKD_OK.
inline void check(gjkd_status status) {
    if (status != GJKD_OK) {
        throw Error(status, gjkd_last_error_code(), gjkd_last_error());
    }
}

/// The identity pose.
inline Pose identity() { return Pose{{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0, 1.0}}; }

/// A translation by (x, y, z), no rotation.
inline Pose at(double x, double y, double z) {
    return Pose{{x, y, z}, {0.0, 0.0, 0.0, 1.0}};
}

/// The quaternion of components w, x, y, z, given in Eigen's constructor
/// order (w first) and stored as a Pose stores it (x, y, z, w).
inline Quat quat(double w, double x, double y, double z) { return Quat{x, y, z, w}; }

/// The rotation by `angle` radians about `axis` (any non-zero length).
inline Quat axis_angle(const std::array<double, 3> &axis, double angle) {
    const double n = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    const double s = n > 0.0 ? std::sin(angle / 2.0) / n : 0.0;
    return Quat{axis[0] * s, axis[1] * s, axis[2] * s, std::cos(angle / 2.0)};
}

/// The rotation by `yaw` about z, then `pitch` about the new y, then
/// `roll` about the newest x (radians): R = Rz(yaw) Ry(pitch) Rx(roll), as
/// URDF's `rpy` and ROS's tf2 setRPY(roll, pitch, yaw).
inline Quat rpy(double roll, double pitch, double yaw) {
    const double cr = std::cos(roll / 2), sr = std::sin(roll / 2);
    const double cp = std::cos(pitch / 2), sp = std::sin(pitch / 2);
    const double cy = std::cos(yaw / 2), sy = std::sin(yaw / 2);
    return Quat{sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
                cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy};
}

/// The product a b: the rotation b, then a. (Named functions, not
/// operators: Pose and Quat are C and std types, which argument-dependent
/// lookup would not find gjkd's operators for.)
inline Quat multiply(const Quat &a, const Quat &b) {
    const double ax = a[0], ay = a[1], az = a[2], aw = a[3];
    const double bx = b[0], by = b[1], bz = b[2], bw = b[3];
    return Quat{aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz};
}

/// `q` applied to the vector `v`.
inline std::array<double, 3> rotate(const Quat &q, const std::array<double, 3> &v) {
    const Quat r = multiply(multiply(q, Quat{v[0], v[1], v[2], 0.0}), Quat{-q[0], -q[1], -q[2], q[3]});
    return {r[0], r[1], r[2]};
}

/// The pose of translation (x, y, z) and rotation `q`.
inline Pose pose(double x, double y, double z, const Quat &q) {
    return Pose{{x, y, z}, {q[0], q[1], q[2], q[3]}};
}

/// The rotation of `p`.
inline Quat rotation_of(const Pose &p) {
    return Quat{p.rotation[0], p.rotation[1], p.rotation[2], p.rotation[3]};
}

/// The composition a b: `b`, expressed in `a`'s frame, placed in the
/// world (a link's pose is compose(its parent's pose, its offset)).
inline Pose compose(const Pose &a, const Pose &b) {
    const Quat qa = rotation_of(a);
    const std::array<double, 3> t =
        rotate(qa, {b.translation[0], b.translation[1], b.translation[2]});
    return pose(a.translation[0] + t[0], a.translation[1] + t[1], a.translation[2] + t[2],
                multiply(qa, rotation_of(b)));
}

/// The inverse of `p`: compose(p, inverse(p)) is the identity.
inline Pose inverse(const Pose &p) {
    const Quat q{-p.rotation[0], -p.rotation[1], -p.rotation[2], p.rotation[3]};
    const std::array<double, 3> t =
        rotate(q, {-p.translation[0], -p.translation[1], -p.translation[2]});
    return pose(t[0], t[1], t[2], q);
}

#ifdef GJKD_WITH_EIGEN
/// `p` as an Eigen isometry (define GJKD_WITH_EIGEN before including this
/// header; gjkd itself needs no Eigen).
inline Eigen::Isometry3d to_eigen(const Pose &p) {
    Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
    iso.linear() =
        Eigen::Quaterniond(p.rotation[3], p.rotation[0], p.rotation[1], p.rotation[2])
            .toRotationMatrix();
    iso.translation() = Eigen::Vector3d(p.translation[0], p.translation[1], p.translation[2]);
    return iso;
}

/// The Pose of an Eigen isometry (its linear part must be a rotation).
inline Pose from_eigen(const Eigen::Isometry3d &iso) {
    const Eigen::Quaterniond q(iso.linear());
    const Eigen::Vector3d t = iso.translation();
    return pose(t.x(), t.y(), t.z(), Quat{q.x(), q.y(), q.z(), q.w()});
}

/// The Pose of an Eigen translation and quaternion.
inline Pose from_eigen(const Eigen::Vector3d &t, const Eigen::Quaterniond &q) {
    return pose(t.x(), t.y(), t.z(), Quat{q.x(), q.y(), q.z(), q.w()});
}
#endif

/// A row asking the distance of `a` and `b` at their stored poses.
inline PairQuery pair(Id a, Id b, const Options *options = nullptr) {
    return gjkd_pair_query_of(a, b, options);
}

/// A row asking the distance of `a` at `pose_a` and `b` at `pose_b`, for
/// this query only.
inline PairQuery pair_at(Id a, const Pose &pose_a, Id b, const Pose &pose_b,
                         const Options *options = nullptr) {
    PairQuery q = gjkd_pair_query_of(a, b, options);
    q.pose_a = pose_a;
    q.pose_b = pose_b;
    q.flags |= GJKD_POSE_A | GJKD_POSE_B;
    return q;
}

/// The default query options.
inline Options default_options() { return gjkd_query_options_default(); }

/// The default scene query options.
inline SceneOptions default_scene_options() { return gjkd_scene_options_default(); }

/// The group of a scene query: a robot or one object by `id`, or (with
/// `id` 0) the listed members; allowed pairs never reported. The vectors
/// are read by each call, not copied here.
struct Group {
    /// A robot or object id, or 0 for `members`.
    Id id = 0;
    /// The members when `id` is 0.
    std::vector<Id> members;
    /// Pairs never to report.
    std::vector<std::array<Id, 2>> allowed;

    /// The C view, valid while this Group lives unchanged.
    gjkd_group view() const {
        return gjkd_group{id, members.empty() ? nullptr : members.data(), members.size(),
                          allowed.empty() ? nullptr : allowed[0].data(), allowed.size()};
    }
};

/// A ball of `radius`.
inline Shape sphere(double radius) {
    return Shape{GJKD_SHAPE_SPHERE, radius, {0, 0, 0}, {0, 0, 0}, nullptr, 0};
}

/// The segment a-b grown by `radius`.
inline Shape capsule(const Vec3 &a, const Vec3 &b, double radius) {
    return Shape{GJKD_SHAPE_CAPSULE, radius, {a[0], a[1], a[2]}, {b[0], b[1], b[2]}, nullptr, 0};
}

/// A box of half extents `h`, grown by `radius` (each half extent grows
/// by it, edges and corners become round).
inline Shape box(const Vec3 &h, double radius = 0.0) {
    return Shape{GJKD_SHAPE_BOX, radius, {h[0], h[1], h[2]}, {0, 0, 0}, nullptr, 0};
}

/// An exact cylinder about z: the disk of `radius` swept over
/// [-half_height, half_height], grown by `rounding` (radius and
/// half-height each grow by it, the rims become round).
inline Shape cylinder(double radius, double half_height, double rounding = 0.0) {
    return Shape{GJKD_SHAPE_CYLINDER, rounding, {radius, half_height, 0}, {0, 0, 0}, nullptr, 0};
}

/// The hull of `count` points (3 doubles each at `xyz`) grown by `radius`.
/// The points are read when the shape is registered, not copied here.
inline Shape polytope(const double *xyz, std::size_t count, double radius = 0.0) {
    return Shape{GJKD_SHAPE_POLYTOPE, radius, {0, 0, 0}, {0, 0, 0}, xyz, count};
}

/// Output arrays of Client::distances(), owned here and reused across
/// calls of the same or a smaller size. Row i answers pair i.
class Distances {
public:
    Distances() = default;
    /// Room for `n` rows.
    explicit Distances(std::size_t n) { resize(n); }

    /// Room for `n` rows (allocates only when growing).
    void resize(std::size_t n) {
        distance.resize(n);
        lower.resize(n);
        upper.resize(n);
        penetration.resize(n);
        point_a.resize(n);
        point_b.resize(n);
        normal.resize(n);
        status.resize(n);
        iterations.resize(n);
        pieces.resize(n);
        error.resize(n);
        warm_started.resize(n);
    }

    /// Rows.
    std::size_t size() const noexcept { return distance.size(); }

    /// The C view of the arrays.
    gjkd_results view() noexcept {
        gjkd_results r{};
        r.distance = distance.data();
        r.lower = lower.data();
        r.upper = upper.data();
        r.penetration = penetration.data();
        r.point_a = point_a.empty() ? nullptr : point_a[0].data();
        r.point_b = point_b.empty() ? nullptr : point_b[0].data();
        r.normal = normal.empty() ? nullptr : normal[0].data();
        r.status = status.data();
        r.iterations = iterations.data();
        r.pieces = pieces.empty() ? nullptr : pieces[0].data();
        r.error = error.data();
        // std::vector<bool> has no array: the flags go through bytes.
        r.warm_started = reinterpret_cast<bool *>(warm_started.data());
        return r;
    }

    /// Whether row `i` started from the pair's last simplex.
    bool warm(std::size_t i) const { return warm_started[i] != 0; }

    std::vector<double> distance;    ///< Distances.
    std::vector<double> lower;       ///< Certified lower bounds.
    std::vector<double> upper;       ///< Certified upper bounds.
    std::vector<double> penetration; ///< Lower bounds on penetration depth.
    std::vector<Vec3> point_a;       ///< Nearest points on A.
    std::vector<Vec3> point_b;       ///< Nearest points on B.
    std::vector<Vec3> normal;        ///< Unit normals from A towards B.
    std::vector<uint32_t> status;    ///< gjkd_query_status values.
    std::vector<uint32_t> iterations; ///< Iterations.
    /// Pieces of A and B that realise the distance (0 for convex objects).
    std::vector<std::array<uint32_t, 2>> pieces;
    std::vector<uint32_t> error;     ///< gjkd_error_code values, 0 if answered.
    /// Whether each query started warm (see warm()); bytes of a bool.
    std::vector<unsigned char> warm_started;
};

static_assert(sizeof(bool) == sizeof(unsigned char), "warm_started holds one bool per byte");

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is three packed doubles");

#if defined(GJKD_ROBOTS)
/// A robot registered from URDF (see Client::register_robot): its links
/// are objects, its joints move them. Owns its gjkd_robot; holds no
/// connection.
class Robot {
public:
    /// Takes ownership of `handle` (from gjkd_register_robot() and kin).
    explicit Robot(gjkd_robot *handle) : handle_(handle) {}
    ~Robot() { gjkd_robot_free(handle_); }
    Robot(const Robot &) = delete;
    Robot &operator=(const Robot &) = delete;
    Robot(Robot &&other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
    Robot &operator=(Robot &&other) noexcept {
        if (this != &other) {
            gjkd_robot_free(handle_);
            handle_ = std::exchange(other.handle_, nullptr);
        }
        return *this;
    }

    /// The C handle; still owned here.
    gjkd_robot *native_handle() const noexcept { return handle_; }
    /// The robot's id: the Group id of scene questions about it. No object
    /// id (remove() does not take it): its links are the objects, see
    /// link(); remove the robot with Client::remove_robot().
    Id id() const { return info().id; }
    /// Number of moving joints.
    std::size_t dof() const { return info().joints; }
    /// Every link's name, in the URDF's order.
    std::vector<std::string> link_names() const {
        std::vector<std::string> names(info().links);
        for (std::size_t i = 0; i < names.size(); ++i) {
            const char *name = nullptr;
            check(gjkd_robot_link(handle_, i, &name, nullptr));
            names[i] = name;
        }
        return names;
    }
    /// The moving joints' names, in position-array order.
    std::vector<std::string> joint_names() const {
        std::vector<std::string> names(info().joints);
        for (std::size_t i = 0; i < names.size(); ++i) {
            const char *name = nullptr;
            check(gjkd_robot_joint(handle_, i, &name, nullptr, nullptr, nullptr));
            names[i] = name;
        }
        return names;
    }
    /// The object id of link `name` (0 for a link without geometry).
    /// Throws GJKD_ERR_INVALID_ARGUMENT with GJKD_CODE_UNKNOWN_NAME for a
    /// name that is no link (looked up here, not on the server).
    Id link(const std::string &name) const {
        Id id = 0;
        check(gjkd_robot_link_id(handle_, name.c_str(), &id));
        return id;
    }
    /// The number of links.
    std::size_t links() const { return info().links; }
    /// Moving joint `index`'s limits (-inf, inf for a continuous joint).
    std::pair<double, double> joint_limits(std::size_t index) const {
        double lower = 0, upper = 0;
        check(gjkd_robot_joint(handle_, index, nullptr, &lower, &upper, nullptr));
        return {lower, upper};
    }
    /// The joint positions last set, in joint_names() order.
    std::vector<double> positions() const {
        std::vector<double> q(dof());
        for (std::size_t i = 0; i < q.size(); ++i) {
            check(gjkd_robot_joint(handle_, i, nullptr, nullptr, nullptr, &q[i]));
        }
        return q;
    }
    /// Every link's pose (URDF order, into `out`, resized to links()) by
    /// forward kinematics, computed here as the server computes it, for
    /// `count` positions (none: the positions last set) and `base` (null:
    /// the base last sent).
    void link_poses(std::vector<Pose> &out, const double *positions = nullptr,
                    std::size_t count = 0, const Pose *base = nullptr,
                    bool clamp = false) const {
        out.resize(links());
        check(gjkd_robot_link_poses(handle_, positions, count, base, clamp, out.data(),
                                    out.size()));
    }
    /// Every link's pose for `positions` and `base`.
    std::vector<Pose> link_poses(const std::vector<double> &positions,
                                 const Pose &base = identity(), bool clamp = false) const {
        std::vector<Pose> out;
        link_poses(out, positions.data(), positions.size(), &base, clamp);
        return out;
    }

private:
    struct Info {
        Id id;
        std::size_t links, joints;
    };
    Info info() const {
        Info i{};
        check(gjkd_robot_info(handle_, &i.id, &i.links, &i.joints));
        return i;
    }

    gjkd_robot *handle_ = nullptr;
};
#endif // GJKD_ROBOTS

/// A connection to a gjkd server. Every method throws gjkd::Error on
/// failure; see gjkd.h for each call's errors.
class Client {
public:
    /// Connects to `service`, waiting up to `connect_timeout_s` seconds (0:
    /// `timeout_s`) for a server; `timeout_s` bounds every later call.
    explicit Client(const std::string &service = "gjkd", double timeout_s = 1.0,
                    double connect_timeout_s = 0.0) {
        check(gjkd_connect(service.c_str(), timeout_s, connect_timeout_s, &handle_));
    }
    /// Closes the connection, on any thread, removing what was registered
    /// with RegistrationOptions::remove_on_close. (Only a call running on
    /// another thread at that moment could stop it: destroying an object
    /// in use is a bug in any case.)
    ~Client() { gjkd_close(handle_); }
    Client(const Client &) = delete;
    Client &operator=(const Client &) = delete;
    Client(Client &&other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
    Client &operator=(Client &&other) noexcept {
        if (this != &other) {
            gjkd_close(handle_);
            handle_ = std::exchange(other.handle_, nullptr);
        }
        return *this;
    }

    /// The C handle, for calls this wrapper lacks; still owned here.
    gjkd_client *native_handle() const noexcept { return handle_; }

    /// Registers `shape` at `pose`, under `name` if not null.
    Id register_shape(const Shape &shape, const Pose &pose = identity(),
                      const char *name = nullptr) {
        Id id = 0;
        check(gjkd_register(handle_, &shape, name, &pose, &id));
        return id;
    }
    /// Registers a ball.
    Id register_sphere(double radius, const Pose &pose = identity(), const char *name = nullptr) {
        return register_shape(sphere(radius), pose, name);
    }
    /// Registers a capsule.
    Id register_capsule(const Vec3 &a, const Vec3 &b, double radius,
                        const Pose &pose = identity(), const char *name = nullptr) {
        return register_shape(capsule(a, b, radius), pose, name);
    }
    /// Registers a box.
    Id register_box(const Vec3 &half_extents, double radius = 0.0,
                    const Pose &pose = identity(), const char *name = nullptr) {
        return register_shape(box(half_extents, radius), pose, name);
    }
    /// Registers the hull of `vertices` grown by `radius`.
    Id register_polytope(const std::vector<Vec3> &vertices, double radius = 0.0,
                         const Pose &pose = identity(), const char *name = nullptr) {
        const double *xyz = vertices.empty() ? nullptr : vertices[0].data();
        return register_shape(polytope(xyz, vertices.size(), radius), pose, name);
    }
    /// Registers a union of convex pieces.
    Id register_compound(const std::vector<Piece> &pieces, const Pose &pose = identity(),
                         const char *name = nullptr) {
        Id id = 0;
        check(gjkd_register_compound(handle_, pieces.data(), pieces.size(), name, &pose, &id));
        return id;
    }
    /// Registers an exact cylinder about z: the disk of `radius` swept over
    /// `[-half_height, half_height]`, grown by `rounding` (see cylinder()).
    Id register_cylinder(double radius, double half_height, double rounding = 0.0,
                         const Pose &pose = identity(), const char *name = nullptr) {
        Id id = 0;
        check(gjkd_register_cylinder(handle_, radius, half_height, rounding, name, &pose, &id));
        return id;
    }
#if defined(GJKD_ROBOTS)
    /// Registers the mesh in an STL, OBJ or COLLADA file, scaled by `scale`
    /// (null: 1), as its hull (`decompose` 0) or a V-HACD decomposition at
    /// that resolution.
    Id register_mesh_file(const std::string &path, const Vec3 *scale = nullptr,
                          uint32_t decompose = 0, const Pose &pose = identity(),
                          const char *name = nullptr) {
        Id id = 0;
        check(gjkd_register_mesh_file(handle_, path.c_str(), scale ? scale->data() : nullptr,
                                      decompose, name, &pose, &id, nullptr));
        return id;
    }
    /// Registers the triangle mesh of `vertices` (and `triangles`, vertex
    /// indices, three per triangle; may be empty for a hull), scaled by
    /// `scale` (null: 1), as its hull (`decompose` 0) or a V-HACD
    /// decomposition at that resolution; what it made into `*info` if not
    /// null.
    Id register_mesh(const std::vector<Vec3> &vertices,
                     const std::vector<std::array<uint32_t, 3>> &triangles = {},
                     const Vec3 *scale = nullptr, uint32_t decompose = 0,
                     const Pose &pose = identity(), const char *name = nullptr,
                     MeshInfo *info = nullptr) {
        Id id = 0;
        check(gjkd_register_mesh(handle_, vertices.empty() ? nullptr : vertices[0].data(),
                                 vertices.size(),
                                 triangles.empty() ? nullptr : triangles[0].data(),
                                 triangles.size(), scale ? scale->data() : nullptr, decompose,
                                 name, &pose, &id, info));
        return id;
    }
    /// register_mesh_file() with what it made into `*info`.
    Id register_mesh_file(const std::string &path, MeshInfo &info, const Vec3 *scale = nullptr,
                          uint32_t decompose = 0, const Pose &pose = identity(),
                          const char *name = nullptr) {
        Id id = 0;
        check(gjkd_register_mesh_file(handle_, path.c_str(), scale ? scale->data() : nullptr,
                                      decompose, name, &pose, &id, &info));
        return id;
    }
    /// Registers a robot from a URDF file (`srdf` and `package_path`, a
    /// `:`-separated folder list, may be null).
    Robot register_robot(const std::string &name, const std::string &urdf_path,
                         const char *srdf_path = nullptr, const char *package_path = nullptr,
                         const Pose &base = identity()) {
        gjkd_robot *robot = nullptr;
        check(gjkd_register_robot(handle_, name.c_str(), urdf_path.c_str(), srdf_path,
                                  package_path, &base, &robot));
        return Robot(robot);
    }
    /// Registers a robot from URDF text (and SRDF text, or null) in
    /// memory; relative mesh paths are relative to `mesh_dir` (null: the
    /// working folder).
    Robot register_robot_text(const std::string &name, const std::string &urdf_text,
                              const char *srdf_text = nullptr, const char *mesh_dir = nullptr,
                              const char *package_path = nullptr,
                              const Pose &base = identity()) {
        gjkd_robot *robot = nullptr;
        check(gjkd_register_robot_text(handle_, name.c_str(), urdf_text.c_str(), srdf_text,
                                       mesh_dir, package_path, &base, &robot));
        return Robot(robot);
    }
    /// The robot named `name` already on the server, given its URDF text
    /// for the joint order and link names.
    Robot open_robot(const std::string &name, const std::string &urdf_text) {
        gjkd_robot *robot = nullptr;
        check(gjkd_open_robot(handle_, name.c_str(), urdf_text.c_str(), &robot));
        return Robot(robot);
    }
    /// Sets every joint of `robot` (`count` positions, in
    /// Robot::joint_names() order, radians or the URDF's length unit) and
    /// its base, if not null, in one round trip; out-of-limit positions
    /// throw unless `clamp`. Allocates nothing: call it every control step.
    void set_joints(Robot &robot, const double *positions, std::size_t count,
                    const Pose *base = nullptr, bool clamp = false) {
        check(gjkd_set_joints(handle_, robot.native_handle(), positions, count, base, clamp));
    }
    /// As above, with a base pose (a temporary will do).
    void set_joints(Robot &robot, const double *positions, std::size_t count, const Pose &base,
                    bool clamp = false) {
        set_joints(robot, positions, count, &base, clamp);
    }
    /// Sets every joint of `robot` (and its base, if not null).
    void set_joints(Robot &robot, const std::vector<double> &positions,
                    const Pose *base = nullptr, bool clamp = false) {
        set_joints(robot, positions.data(), positions.size(), base, clamp);
    }
    /// Sets every joint of `robot` from a fixed-size array.
    template <std::size_t N>
    void set_joints(Robot &robot, const std::array<double, N> &positions,
                    const Pose *base = nullptr, bool clamp = false) {
        set_joints(robot, positions.data(), N, base, clamp);
    }
#ifdef GJKD_HAS_SPAN
    /// Sets every joint of `robot` (C++20).
    void set_joints(Robot &robot, std::span<const double> positions, const Pose *base = nullptr,
                    bool clamp = false) {
        set_joints(robot, positions.data(), positions.size(), base, clamp);
    }
#endif
    /// Sets the joints named `names[i]` to `values[i]`; the others keep
    /// their positions last set.
    void set_joints_by_name(Robot &robot, const std::vector<std::string> &names,
                            const std::vector<double> &values, bool clamp = false) {
        if (names.size() != values.size()) {
            throw Error(GJKD_ERR_INVALID_ARGUMENT, GJKD_CODE_OK,
                        "set_joints_by_name: " + std::to_string(names.size()) + " names for " +
                            std::to_string(values.size()) + " values");
        }
        std::vector<const char *> c_names;
        c_names.reserve(names.size());
        for (const std::string &n : names) c_names.push_back(n.c_str());
        check(gjkd_set_joints_by_name(handle_, robot.native_handle(), c_names.data(),
                                      values.data(), values.size(), clamp));
    }
#endif // GJKD_ROBOTS
    /// Removes an object this client registered. (A robot's link so
    /// removed leaves a hole: use remove_robot(); a robot's id is no
    /// object id.)
    void remove(Id id) { check(gjkd_remove(handle_, id)); }
#if defined(GJKD_ROBOTS)
    /// Removes `robot` as a whole: its kinematics and every link object,
    /// all or nothing. `robot` then names nothing on the server.
    void remove_robot(const Robot &robot) {
        check(gjkd_remove_robot(handle_, robot.native_handle()));
    }
#endif // GJKD_ROBOTS
    /// Removes the robot named `name` as a whole.
    void remove_robot(const std::string &name) {
        check(gjkd_remove_robot_named(handle_, name.c_str()));
    }
    /// How later registrations treat taken names (reuse_names: get the
    /// object or robot already under the name, as a restarted node needs)
    /// and this Client's end (remove_on_close).
    void set_registration_options(const RegistrationOptions &options) {
        check(gjkd_set_registration_options(handle_, &options));
    }
    /// The id of the object named `name`.
    Id lookup(const std::string &name) {
        Id id = 0;
        check(gjkd_lookup(handle_, name.c_str(), &id));
        return id;
    }

    /// Stores the pose of `id`.
    void set_pose(Id id, const Pose &pose) { check(gjkd_set_pose(handle_, id, &pose)); }
    /// Stores `count` poses in one round trip.
    void set_poses(const Id *ids, const Pose *poses, std::size_t count) {
        check(gjkd_set_poses(handle_, ids, poses, count));
    }
    /// Stores poses[i] for ids[i] (the sizes must agree).
    void set_poses(const std::vector<Id> &ids, const std::vector<Pose> &poses) {
        same_size(ids.size(), poses.size());
        set_poses(ids.data(), poses.data(), ids.size());
    }
    /// The stored poses of `count` objects into `poses`, bit for bit as
    /// the server holds them (a robot link's as its joints put it), and
    /// each entry's code into `errors`: GJKD_CODE_OK, or
    /// GJKD_CODE_UNKNOWN_OBJECT for an id the server does not hold (its
    /// pose the identity; the others are answered all the same).
    void get_poses(const Id *ids, std::size_t count, Pose *poses, std::uint32_t *errors) {
        check(gjkd_get_poses(handle_, ids, count, poses, errors));
    }
    /// The stored poses of `ids`, in order; throws Error (GJKD_ERR_REJECTED,
    /// GJKD_CODE_UNKNOWN_OBJECT, the row named) if an id is unknown.
    std::vector<Pose> get_poses(const std::vector<Id> &ids) {
        std::vector<Pose> poses(ids.size());
        std::vector<std::uint32_t> errors(ids.size());
        get_poses(ids.data(), ids.size(), poses.data(), errors.data());
        for (std::size_t i = 0; i < ids.size(); ++i) {
            if (errors[i] != GJKD_CODE_OK) {
                throw Error(GJKD_ERR_REJECTED, errors[i],
                            "get_poses: ids[" + std::to_string(i) + "] is no object");
            }
        }
        return poses;
    }

    /// The distance between `a` and `b` at their stored poses, or at
    /// `pose_a` / `pose_b` if not null.
    Answer distance(Id a, Id b, const Pose *pose_a = nullptr, const Pose *pose_b = nullptr,
                    const Options *options = nullptr) {
        Answer answer{};
        check(gjkd_distance(handle_, a, b, pose_a, pose_b, options, &answer));
        return answer;
    }
    /// The distance between `a` at `pose_a` and `b` at `pose_b`, for this
    /// query only (temporaries will do; the stored poses are neither used
    /// nor changed).
    Answer distance(Id a, Id b, const Pose &pose_a, const Pose &pose_b,
                    const Options *options = nullptr) {
        return distance(a, b, &pose_a, &pose_b, options);
    }
    /// The distance between `a` and `b` at their stored poses, with
    /// `options`.
    Answer distance(Id a, Id b, const Options &options) {
        return distance(a, b, nullptr, nullptr, &options);
    }

    /// The distances of `count` pairs (`2 * count` ids) into `out`, resized
    /// to `count` rows. Rows that fail carry their code in `out.error`.
    void distances(const Id *pairs, std::size_t count, Distances &out,
                   const Pose *poses_a = nullptr, const Pose *poses_b = nullptr,
                   const Options *options = nullptr) {
        if (out.size() != count) out.resize(count);
        gjkd_results view = out.view();
        check(gjkd_distances(handle_, pairs, count, poses_a, poses_b, options, &view));
    }
    /// The distances of `pairs` into `out`.
    void distances(const std::vector<std::array<Id, 2>> &pairs, Distances &out,
                   const Options *options = nullptr) {
        const Id *ids = pairs.empty() ? nullptr : pairs[0].data();
        distances(ids, pairs.size(), out, nullptr, nullptr, options);
    }
    /// The distances of `pairs` at `poses_a` and `poses_b` (as many each,
    /// or empty for the stored poses), for these queries only, into `out`.
    void distances(const std::vector<std::array<Id, 2>> &pairs, const std::vector<Pose> &poses_a,
                   const std::vector<Pose> &poses_b, Distances &out,
                   const Options *options = nullptr) {
        for (std::size_t n : {poses_a.size(), poses_b.size()}) {
            if (n != 0 && n != pairs.size()) {
                throw Error(GJKD_ERR_INVALID_ARGUMENT, GJKD_CODE_OK,
                            "distances: " + std::to_string(n) + " poses for " +
                                std::to_string(pairs.size()) + " pairs");
            }
        }
        const Id *ids = pairs.empty() ? nullptr : pairs[0].data();
        distances(ids, pairs.size(), out, poses_a.empty() ? nullptr : poses_a.data(),
                  poses_b.empty() ? nullptr : poses_b.data(), options);
    }

    /// The answers of `count` rows (made by pair() or pair_at(), which
    /// take the options) into `out[0..count)`: the fastest batch, copied in
    /// one piece each way. Rows that fail carry their code in `error`.
    void query_pairs(const PairQuery *queries, std::size_t count, Result *out) {
        check(gjkd_query_pairs(handle_, queries, count, out));
    }
    /// The answers of `queries` into `out`, resized to match (allocates
    /// only when growing).
    void query_pairs(const std::vector<PairQuery> &queries, std::vector<Result> &out) {
        if (out.size() != queries.size()) out.resize(queries.size());
        query_pairs(queries.data(), queries.size(), out.data());
    }
    /// As query_pairs(), for rows that may ask for their gradient
    /// (`row.flags |= GJKD_PAIR_GRADIENT`): the gradient of the k-th row
    /// that asks into `gradients[k]` (room for `gradient_count`); returns
    /// how many were written. Only rows that ask carry one.
    std::size_t query_pairs(const PairQuery *queries, std::size_t count, Result *out,
                            Gradient *gradients, std::size_t gradient_count) {
        std::size_t written = 0;
        check(gjkd_query_pairs_gradients(handle_, queries, count, out, gradients, gradient_count,
                                         &written));
        return written;
    }
    /// As above with vectors: `out` resized to match `queries`, `gradients`
    /// to the rows that ask (both allocate only when growing).
    std::size_t query_pairs(const std::vector<PairQuery> &queries, std::vector<Result> &out,
                            std::vector<Gradient> &gradients) {
        if (out.size() != queries.size()) out.resize(queries.size());
        std::size_t asked = 0;
        for (const PairQuery &q : queries) asked += (q.flags & GJKD_PAIR_GRADIENT) != 0;
        if (gradients.size() < asked) gradients.resize(asked);
        return query_pairs(queries.data(), queries.size(), out.data(), gradients.data(),
                           gradients.size());
    }

#ifdef GJKD_HAS_SPAN
    /// The answers of `queries` into `out`, which must be as long (C++20).
    void query_pairs(std::span<const PairQuery> queries, std::span<Result> out) {
        if (out.size() != queries.size()) {
            throw Error(GJKD_ERR_INVALID_ARGUMENT, GJKD_CODE_OK,
                        "query_pairs: " + std::to_string(out.size()) + " result rows for " +
                            std::to_string(queries.size()) + " queries");
        }
        query_pairs(queries.data(), queries.size(), out.data());
    }
    /// Stores poses[i] for ids[i] (C++20).
    void set_poses(std::span<const Id> ids, std::span<const Pose> poses) {
        same_size(ids.size(), poses.size());
        set_poses(ids.data(), poses.data(), ids.size());
    }
    /// The distances of `pairs` into `out` (C++20).
    void distances(std::span<const std::array<Id, 2>> pairs, Distances &out,
                   const Options *options = nullptr) {
        const Id *ids = pairs.empty() ? nullptr : pairs[0].data();
        distances(ids, pairs.size(), out, nullptr, nullptr, options);
    }
#endif

    /// What the server said about itself at the last (re)connection.
    gjkd_info server_info() {
        gjkd_info info{};
        check(gjkd_server_info(handle_, &info));
        return info;
    }
    /// The server's counters.
    gjkd_server_stats stats() {
        gjkd_server_stats s{};
        check(gjkd_stats(handle_, &s));
        return s;
    }

    /// Each member's nearest object outside `group`, into `rows` (its size
    /// is the room; rows past `written` are left alone).
    SceneSummary clearance(const Group &group, std::vector<SceneRow> &rows,
                           const SceneOptions *options = nullptr) {
        SceneSummary s{};
        const gjkd_group g = group.view();
        check(gjkd_clearance(handle_, &g, options, rows.data(), rows.size(), &s));
        return s;
    }
    /// Every pair within `margin`, into `rows`.
    SceneSummary within(const Group &group, double margin, std::vector<SceneRow> &rows,
                        const SceneOptions *options = nullptr) {
        SceneSummary s{};
        const gjkd_group g = group.view();
        check(gjkd_within(handle_, &g, margin, options, rows.data(), rows.size(), &s));
        return s;
    }
    /// The `k` objects nearest to `object`, into `rows`.
    SceneSummary nearest(Id object, uint32_t k, std::vector<SceneRow> &rows,
                         const SceneOptions *options = nullptr) {
        SceneSummary s{};
        check(gjkd_nearest(handle_, object, k, options, rows.data(), rows.size(), &s));
        return s;
    }
    /// `question` (a gjkd_path_question) at every step of a motion of
    /// `moving`: `poses` holds `poses.size() / moving.size()` steps.
    SceneSummary path(const Group &group, gjkd_path_question question, double margin,
                      const std::vector<Id> &moving, const std::vector<Pose> &poses,
                      std::vector<SceneRow> &rows, const SceneOptions *options = nullptr) {
        if (moving.empty() || poses.size() % moving.size() != 0) {
            throw Error(GJKD_ERR_INVALID_ARGUMENT, GJKD_CODE_OK,
                        "path: " + std::to_string(poses.size()) +
                            " poses are no whole number of steps of " +
                            std::to_string(moving.size()) + " objects");
        }
        SceneSummary s{};
        const gjkd_group g = group.view();
        check(gjkd_path(handle_, &g, static_cast<uint32_t>(question), margin, moving.data(),
                        moving.size(), poses.data(), poses.size() / moving.size(), options,
                        rows.data(), rows.size(), &s));
        return s;
    }

#if defined(GJKD_ROBOTS)
    /// `question` at every step of a motion of `robot` given as joint
    /// positions: `positions` holds `positions.size() / robot.dof()` steps
    /// of `dof` positions each (in Robot::joint_names() order). Nothing
    /// moves on the server; `options->clamp` clamps positions outside
    /// their limits instead of throwing.
    SceneSummary path_joints(const Group &group, gjkd_path_question question, double margin,
                             const Robot &robot, const std::vector<double> &positions,
                             std::vector<SceneRow> &rows, const SceneOptions *options = nullptr) {
        const std::size_t dof = robot.dof();
        if (dof == 0 || positions.size() % dof != 0) {
            throw Error(GJKD_ERR_INVALID_ARGUMENT, GJKD_CODE_OK,
                        "path_joints: " + std::to_string(positions.size()) +
                            " positions are no whole number of steps of " +
                            std::to_string(dof) + " joints");
        }
        SceneSummary s{};
        const gjkd_group g = group.view();
        check(gjkd_path_joints(handle_, &g, static_cast<uint32_t>(question), margin,
                               robot.native_handle(), positions.data(), positions.size() / dof,
                               options, rows.data(), rows.size(), &s));
        return s;
    }
#endif // GJKD_ROBOTS

private:
    static void same_size(std::size_t a, std::size_t b) {
        if (a != b) {
            throw Error(GJKD_ERR_INVALID_ARGUMENT, GJKD_CODE_OK,
                        "set_poses: " + std::to_string(a) + " ids for " + std::to_string(b) +
                            " poses");
        }
    }

    gjkd_client *handle_ = nullptr;
};

static_assert(sizeof(std::array<Id, 2>) == 2 * sizeof(Id), "a pair is two packed ids");

} // namespace gjkd

#endif // GJKD_HPP
