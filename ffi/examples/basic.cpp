// basic.cpp: the C example through the C++ wrapper: connect, register
// shapes, store poses, ask a batch of pairs and one pair, check them
// against their analytic values.
//
//   gjkd serve &
//   c++ -std=c++17 basic.cpp -I ffi/include -L target/release -lgjkd_c -o basic_cpp
//   LD_LIBRARY_PATH=target/release ./basic_cpp [SERVICE]
//
// Exits 0 when every answer is within 1e-9 of the analytic one.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gjkd.hpp"

namespace {

int failures = 0;

void expect(const char *what, double got, double want) {
    bool ok = std::fabs(got - want) <= 1e-9;
    std::printf("%-22s %.12f (expected %.12f)%s\n", what, got, want, ok ? "" : "  WRONG");
    failures += !ok;
}

} // namespace

int main(int argc, char **argv) {
    try {
        gjkd::Client client(argc > 1 ? argv[1] : "gjkd", 1.0, 10.0);

        // Shapes, registered once, at their initial poses.
        gjkd::Id box = client.register_box({1, 1, 1}, 0.0, gjkd::identity(), "basic-cpp-box");
        gjkd::Id ball = client.register_sphere(0.5, gjkd::at(3, 0, 0));
        gjkd::Id rod = client.register_capsule({0, -1, 0}, {0, 1, 0}, 0.25);
        std::vector<gjkd::Vec3> cube;
        for (int i = 0; i < 8; i++) {
            cube.push_back({i & 1 ? .5 : -.5, i & 2 ? .5 : -.5, i & 4 ? .5 : -.5});
        }
        gjkd::Id block = client.register_polytope(cube);
        gjkd::Id dumbbell = client.register_compound({
            {gjkd::at(-1, 0, 0), gjkd::sphere(0.3)},
            {gjkd::at(1, 0, 0), gjkd::sphere(0.3)},
        });
        expect("lookup gives the id", client.lookup("basic-cpp-box") == box, 1.0);

        // Poses of three objects in one round trip.
        client.set_poses({rod, block, dumbbell},
                         {gjkd::at(0, 5, 0), gjkd::at(-4, 0, 0), gjkd::at(0, -5, 0)});

        // A batch, into arrays kept across calls.
        std::vector<std::array<gjkd::Id, 2>> pairs = {
            {box, ball}, {box, rod}, {box, block}, {ball, rod}, {box, dumbbell}, {box, 0xdead}};
        gjkd::Distances out;
        client.distances(pairs, out);
        const double want[] = {1.5, 2.75, 2.5, 4.25, 3.7};
        const char *names[] = {"box-sphere", "box-capsule", "box-polytope", "sphere-capsule",
                               "box-compound"};
        for (std::size_t i = 0; i < 5; i++) {
            expect(names[i], out.distance[i], want[i]);
            failures += out.error[i] != GJKD_CODE_OK;
            failures += !(out.lower[i] <= out.distance[i] && out.distance[i] <= out.upper[i]);
        }
        expect("box-sphere point_a.x", out.point_a[0][0], 1.0);
        expect("box-sphere point_b.x", out.point_b[0][0], 2.5);
        std::printf("unknown pair           %s\n", gjkd_error_code_name(out.error[5]));
        failures += out.error[5] != GJKD_CODE_UNKNOWN_OBJECT;

        // The same pairs as rows, poses given per row: the fastest batch.
        std::vector<gjkd::PairQuery> rows = {
            gjkd::pair(box, ball),
            gjkd::pair_at(box, gjkd::identity(), ball, gjkd::at(0, 0, -5)),
            gjkd::pair(box, 0xdead)};
        std::vector<gjkd::Result> answers;
        client.query_pairs(rows, answers);
        expect("rows box-sphere", answers[0].distance, 1.5);
        expect("rows box-sphere below", answers[1].distance, 3.5);
        failures += answers[2].error != GJKD_CODE_UNKNOWN_OBJECT;

        // One pair at a pose given for this query only.
        gjkd::Pose above = gjkd::at(0, 0, 4);
        expect("box-sphere above", client.distance(box, ball, nullptr, &above).distance, 2.5);

        // An exact cylinder: its bottom cap at z = 9, the box's top at 1.
        gjkd::Id can = client.register_cylinder(0.5, 1.0, 0.0, gjkd::at(0, 0, 10));
        expect("box-cylinder", client.distance(box, can).distance, 8.0);

        // A robot from URDF: a rod of radius 0.1 hanging 1 below its mount,
        // swung by one joint, in one round trip per move.
        const std::string urdf =
            (std::filesystem::temp_directory_path() / "gjkd-basic-pendulum.urdf").string();
        std::ofstream(urdf) << R"(<robot name="pendulum">
  <link name="mount"/>
  <link name="rod"><collision><origin xyz="0 0 -0.5"/>
    <geometry><cylinder radius="0.1" length="1"/></geometry></collision></link>
  <joint name="swing" type="revolute"><parent link="mount"/><child link="rod"/>
    <axis xyz="0 1 0"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
</robot>)";
        gjkd::Robot pendulum =
            client.register_robot("basic-cpp-pendulum", urdf, nullptr, nullptr, gjkd::at(0, 0, 20));
        gjkd::Id floor_ball = client.register_sphere(0.5, gjkd::at(0, 0, 17));
        expect("rod hanging", client.distance(pendulum.link("rod"), floor_ball).distance, 1.5);
        client.set_joints(pendulum, {std::acos(0.0)});
        expect("rod swung level", client.distance(pendulum.link("rod"), floor_ball).distance, 2.4);
        // The swing back as a candidate motion: the clearance at each step
        // of joint positions, nothing moved on the server.
        gjkd::Group arm;
        arm.id = pendulum.id();
        std::vector<gjkd::SceneRow> steps(4);
        gjkd::SceneSummary swing = client.path_joints(arm, GJKD_PATH_CLEARANCE, 0.0, pendulum,
                                                      {std::acos(0.0), 0.0}, steps);
        failures += swing.steps != 2 || swing.written != 2;
        expect("path: level", steps[0].answer.distance, 2.4);
        expect("path: hanging", steps[1].answer.distance, 1.5);
        expect("rod still level", client.distance(pendulum.link("rod"), floor_ball).distance, 2.4);
        std::remove(urdf.c_str());

        // A refused call throws, with the status, the server's code and words.
        try {
            client.lookup("no-such-object");
            failures++;
        } catch (const gjkd::Error &e) {
            std::printf("lookup of a missing name: %s, %s: %s\n", gjkd_status_name(e.status()),
                        gjkd_error_code_name(e.code()), e.what());
            failures += e.status() != GJKD_ERR_REJECTED || e.code() != GJKD_CODE_UNKNOWN_NAME;
        }

        for (gjkd::Id id : {box, ball, rod, block, dumbbell}) client.remove(id);
    } catch (const gjkd::Error &e) {
        std::fprintf(stderr, "failed: %s: %s\n", gjkd_status_name(e.status()), e.what());
        return 1;
    }
    std::printf(failures ? "FAILED (%d)\n" : "ok\n", failures);
    return failures ? 1 : 0;
}
