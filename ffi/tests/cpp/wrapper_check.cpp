// wrapper_check.cpp: what a C++ developer meets through gjkd.hpp, each
// checked against an analytic answer or the documented error. Arguments:
// SERVICE. Prints one line per check and "ok" last when all held.
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "gjkd.hpp"

namespace {

int failures = 0;

void expect(const char *what, double got, double want, double tol = 1e-9) {
    const bool ok = std::fabs(got - want) <= tol;
    std::printf("%-40s %.12g (expected %.12g)%s\n", what, got, want, ok ? "" : "  WRONG");
    failures += !ok;
}

void expect_true(const char *what, bool ok) {
    std::printf("%-40s %s\n", what, ok ? "yes" : "no  WRONG");
    failures += !ok;
}

// Runs `call`, which must throw a gjkd::Error of `status` and `code`.
template <typename F>
void expect_error(const char *what, gjkd_status status, gjkd_error_code code, F call) {
    try {
        call();
        std::printf("%-40s no error  WRONG\n", what);
        failures++;
    } catch (const gjkd::Error &e) {
        const bool ok = e.status() == status && e.code() == code;
        std::printf("%-40s %s %s%s\n", what, gjkd_status_name(e.status()),
                    gjkd_error_code_name(e.code()), ok ? "" : "  WRONG");
        failures += !ok;
    }
}

// Two links: a 0.2 x 0.2 x 0.2 box base and a ball of radius 0.1 on an
// arm 1 long, turned about z by "turn".
const char *URDF = R"(<robot name="arm">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="tip"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
  <joint name="turn" type="revolute"><parent link="base"/><child link="tip"/>
    <origin xyz="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>)";

// The same arm, the tip reached through a fixed offset of 1 along x.
const char *URDF_OFFSET = R"(<robot name="arm">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="hub"/>
  <link name="tip"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>
  <joint name="turn" type="revolute"><parent link="base"/><child link="hub"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="reach" type="fixed"><parent link="hub"/><child link="tip"/>
    <origin xyz="1 0 0"/></joint>
</robot>)";

} // namespace

int main(int argc, char **argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: wrapper_check SERVICE\n");
        return 2;
    }
    const std::string service = argv[1];
    static_assert(std::is_same<decltype(std::declval<gjkd::Error>().code()), gjkd_error_code>::value,
                  "Error::code() is the enum");
    try {
        gjkd::Client client(service, 2.0, 10.0);
        const gjkd::Id box = client.register_box({1, 1, 1});
        const gjkd::Id ball = client.register_sphere(0.5, gjkd::at(3, 0, 0));

        // Poses by value, temporaries allowed.
        expect("distance at temporaries", client.distance(box, ball, gjkd::at(0, 0, 0),
                                                          gjkd::at(0, 5, 0)).distance, 3.5);

        // Rotation helpers: the box turned 45 degrees about z reaches
        // sqrt(2) along x.
        const double pi = std::acos(-1.0);
        const gjkd::Pose turned = gjkd::pose(0, 0, 0, gjkd::axis_angle({0, 0, 1}, pi / 4));
        expect("box turned by axis_angle", client.distance(box, ball, turned, gjkd::at(3, 0, 0))
                                               .distance, 2.5 - std::sqrt(2.0));
        const gjkd::Pose by_rpy = gjkd::pose(0, 0, 0, gjkd::rpy(0, 0, pi / 4));
        expect("rpy yaw = axis_angle z", by_rpy.rotation[2], turned.rotation[2]);
        expect("quat() takes w first", gjkd::quat(1, 0, 0, 0)[3], 1.0);
        const gjkd::Pose p = gjkd::pose(1, 2, 3, gjkd::rpy(0.3, -0.2, 1.1));
        const gjkd::Pose round = gjkd::compose(p, gjkd::inverse(p));
        expect("p * inverse(p) translation", std::fabs(round.translation[0]) +
                                                 std::fabs(round.translation[1]) +
                                                 std::fabs(round.translation[2]), 0.0, 1e-12);
        expect("p * inverse(p) rotation w", std::fabs(round.rotation[3]), 1.0, 1e-12);
        const gjkd::Pose moved =
            gjkd::compose(gjkd::at(0, 0, 2), gjkd::pose(1, 0, 0, gjkd::rpy(0, 0, pi / 2)));
        expect("composition places b in a", moved.translation[2], 2.0);
#ifdef GJKD_WITH_EIGEN
        const Eigen::Isometry3d iso = gjkd::to_eigen(p);
        const gjkd::Pose back = gjkd::from_eigen(iso);
        double diff = 0;
        for (int i = 0; i < 3; i++) diff += std::fabs(back.translation[i] - p.translation[i]);
        for (int i = 0; i < 4; i++) diff += std::fabs(std::fabs(back.rotation[i]) -
                                                      std::fabs(p.rotation[i]));
        expect("eigen round trip", diff, 0.0, 1e-12);
        const Eigen::Vector3d x = iso * Eigen::Vector3d(1, 0, 0);
        const std::array<double, 3> y = gjkd::rotate(gjkd::rotation_of(p), {1, 0, 0});
        expect("eigen rotates as rotate()", x.x() - 1 - y[0], 0.0, 1e-12);
#endif

        // "Grown by r": a rounded box's half extents and a rounded
        // cylinder's radius and half-height grow by r.
        const gjkd::Id rounded = client.register_box({1, 1, 1}, 0.25, gjkd::at(0, 10, 0));
        expect("rounded box grows by r", client.distance(rounded, ball, gjkd::at(0, 0, 0),
                                                         gjkd::at(3, 0, 0)).distance, 1.25);
        const gjkd::Id can = client.register_shape(gjkd::cylinder(0.5, 1.0, 0.1), gjkd::at(0, 0, 10));
        expect("rounded cylinder grows by r", client.distance(box, can).distance, 7.9);

        // A translation no query could use is refused when set, and one
        // fault has one class and code in every call.
        const auto invalid = GJKD_ERR_INVALID_ARGUMENT;
        const auto non_finite = GJKD_CODE_NON_FINITE_POSE;
        expect_error("set_pose 1e305", invalid, non_finite,
                     [&] { client.set_pose(ball, gjkd::at(1e305, 0, 0)); });
        const double nan = std::nan("");
        expect_error("set_pose NaN", invalid, non_finite,
                     [&] { client.set_pose(ball, gjkd::at(nan, 0, 0)); });
        expect_error("distance at NaN", invalid, non_finite,
                     [&] { client.distance(box, ball, gjkd::at(0, nan, 0), gjkd::identity()); });
        expect("stored pose unchanged", client.distance(box, ball).distance, 1.5);

        // A robot, from text, moved without allocating, its link poses by
        // forward kinematics.
        gjkd::Robot arm = client.register_robot_text("wrapper-arm", URDF_OFFSET);
        expect("robot dof", static_cast<double>(arm.dof()), 1.0);
        const gjkd::Id tip = arm.link("tip");
        const gjkd::Id target = client.register_sphere(0.2, gjkd::at(0, 3, 0));
        expect("tip at rest", client.distance(tip, target).distance,
               std::hypot(1.0, 3.0) - 0.3);
        const double quarter[1] = {pi / 2};
        client.set_joints(arm, quarter, 1);
        expect("tip turned (pointer + count)", client.distance(tip, target).distance, 2.0 - 0.3);
        client.set_joints(arm, std::array<double, 1>{0.0});
        expect("tip back (std::array)", client.distance(tip, target).distance,
               std::hypot(1.0, 3.0) - 0.3);
#ifdef GJKD_HAS_SPAN
        std::vector<double> q{pi / 2};
        client.set_joints(arm, std::span<const double>(q));
        expect("tip turned (span)", client.distance(tip, target).distance, 1.7);
#endif
        client.set_joints_by_name(arm, {"turn"}, {pi / 2});
        expect("set_joints_by_name", arm.positions()[0], pi / 2);
        std::vector<gjkd::Pose> poses;
        arm.link_poses(poses);
        expect("link_poses: tip y", poses[2].translation[1], 1.0, 1e-12);
        const std::vector<gjkd::Pose> lifted = arm.link_poses({0.0}, gjkd::at(0, 0, 5));
        expect("link_poses at a base: tip", lifted[2].translation[0] + lifted[2].translation[2],
               6.0, 1e-12);
        client.set_joints(arm, quarter, 1, gjkd::at(0, 0, 0));
        expect_error("NaN joint", invalid, non_finite, [&] {
            const double bad[1] = {nan};
            client.set_joints(arm, bad, 1);
        });
        expect_error("link(\"nope\") is local", invalid, GJKD_CODE_UNKNOWN_NAME,
                     [&] { arm.link("nope"); });
        expect_error("remove(robot id)", GJKD_ERR_REJECTED, GJKD_CODE_UNKNOWN_OBJECT,
                     [&] { client.remove(arm.id()); });

        // Another client finds the robot by name and moves it, from
        // another thread; a Client made on one thread is used and
        // destroyed on another.
        gjkd::Client other(service, 2.0);
        gjkd::Robot found = other.open_robot("wrapper-arm", URDF_OFFSET);
        expect_true("open_robot finds the links", found.link("tip") == tip);
        std::thread([&other, &found] {
            other.set_joints(found, std::vector<double>{0.0});
            gjkd::Client moved = std::move(other);
            (void)moved.stats();
        }).join();
        expect("moved from another thread", client.distance(tip, target).distance,
               std::hypot(1.0, 3.0) - 0.3);

        // Removing the robot takes every link; the name is free again.
        client.remove_robot(arm);
        expect_error("link gone with its robot", GJKD_ERR_REJECTED, GJKD_CODE_UNKNOWN_OBJECT,
                     [&] { client.distance(tip, target); });
        expect_error("its name gone", GJKD_ERR_REJECTED, GJKD_CODE_UNKNOWN_NAME,
                     [&] { client.lookup("wrapper-arm/tip"); });
        gjkd::Robot again = client.register_robot_text("wrapper-arm", URDF);
        expect_true("registered again", again.link("tip") != 0);

        // A restarted node: names taken, then found with reuse_names.
        const gjkd::Id named = client.register_sphere(0.1, gjkd::at(0, 0, -5), "wrapper-named");
        expect_error("name taken", GJKD_ERR_REJECTED, GJKD_CODE_NAME_TAKEN,
                     [&] { client.register_sphere(0.1, gjkd::identity(), "wrapper-named"); });
        {
            gjkd::Client restarted(service, 2.0);
            restarted.set_registration_options({true, false});
            expect_true("register-or-get: object",
                        restarted.register_sphere(0.1, gjkd::identity(), "wrapper-named") == named);
            gjkd::Robot back = restarted.register_robot_text("wrapper-arm", URDF);
            expect_true("register-or-get: robot", back.link("tip") == again.link("tip"));
        }

        // Objects that end with their client, closed on another thread.
        {
            gjkd::Client scratch(service, 2.0);
            scratch.set_registration_options({false, true});
            scratch.register_sphere(0.1, gjkd::identity(), "wrapper-scratch");
            scratch.register_robot_text("wrapper-scratch-arm", URDF);
            std::thread([c = std::move(scratch)]() mutable { gjkd::Client gone = std::move(c); })
                .join();
        }
        expect_error("ended with its client", GJKD_ERR_REJECTED, GJKD_CODE_UNKNOWN_NAME,
                     [&] { client.lookup("wrapper-scratch"); });
        expect_error("its robot too", GJKD_ERR_REJECTED, GJKD_CODE_UNKNOWN_NAME,
                     [&] { client.lookup("wrapper-scratch-arm/tip"); });

        // A mesh from arrays: a unit cube as eight vertices, its hull.
        std::vector<gjkd::Vec3> cube;
        for (int i = 0; i < 8; i++) cube.push_back({i & 1 ? .5 : -.5, i & 2 ? .5 : -.5,
                                                    i & 4 ? .5 : -.5});
        gjkd::MeshInfo info{};
        const gjkd::Id mesh = client.register_mesh(cube, {}, nullptr, 0, gjkd::at(-4, 0, 0),
                                                   nullptr, &info);
        expect("mesh hull pieces", static_cast<double>(info.pieces), 1.0);
        expect("mesh hull deviation", info.deviation, 0.0);
        expect("mesh distance", client.distance(box, mesh).distance, 2.5);

        // Distances: the pieces and warm-start columns.
        const gjkd::Id bells = client.register_compound({
            {gjkd::at(-1, 0, 0), gjkd::sphere(0.3)},
            {gjkd::at(1, 0, 0), gjkd::sphere(0.3)},
        }, gjkd::at(0, -5, 0));
        const gjkd::Id right = client.register_sphere(0.5, gjkd::at(4, -5, 0));
        gjkd::Distances out;
        client.distances({{bells, right}, {bells, right}}, out);
        client.distances({{bells, right}}, out);
        expect("compound piece", out.pieces[0][0], 1.0);
        expect("compound distance", out.distance[0], 2.2);
        expect_true("second query warm", out.warm(0));
        client.distances({{box, ball}}, {gjkd::at(0, 0, 0)}, {gjkd::at(0, 0, 4)}, out);
        expect("distances at poses", out.distance[0], 2.5);
        client.distances(std::vector<std::array<gjkd::Id, 2>>{}, out);
        expect("no pairs, no rows", static_cast<double>(out.size()), 0.0);

        // An empty group has no rows.
        std::vector<gjkd::SceneRow> rows(4);
        const gjkd::SceneSummary none = client.clearance(gjkd::Group{}, rows);
        expect("empty group: rows", static_cast<double>(none.written + none.total), 0.0);

        for (gjkd::Id id : {box, ball, rounded, can, target, named, mesh, bells, right}) {
            client.remove(id);
        }
        client.remove_robot(again);
    } catch (const gjkd::Error &e) {
        std::fprintf(stderr, "failed: %s %s: %s\n", gjkd_status_name(e.status()),
                     gjkd_error_code_name(e.code()), e.what());
        return 1;
    }
    std::printf(failures ? "FAILED (%d)\n" : "ok\n", failures);
    return failures ? 1 : 0;
}
