/*
 * gradient.c: distance gradients through the C API. A one-joint arm (a
 * 1 m rod turning about z) and a ball beside it: the pair's gradient with
 * respect to the joint (a gjkd_pair_query row flagged GJKD_PAIR_GRADIENT)
 * and every scene row's (gjkd_scene_options.gradients), checked against
 * the analytic value: turning the joint towards the ball closes the gap
 * at 0.8 m per radian.
 *
 *   gjkd serve &                  # in another terminal
 *   cc -std=c99 gradient.c -I ffi/include -L target/release -lgjkd_c -o gradient
 *   LD_LIBRARY_PATH=target/release ./gradient [SERVICE]
 *
 * Exits 0 when every value is within 1e-9 of the analytic one.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "gjkd.h"

static int failures = 0;

static void check(gjkd_status status, const char *what) {
    if (status != GJKD_OK) {
        fprintf(stderr, "%s failed: %s: %s\n", what, gjkd_status_name(status),
                gjkd_last_error());
        exit(1);
    }
}

static void expect(const char *what, double got, double want) {
    int ok = fabs(got - want) <= 1e-9;
    printf("%-22s %.12f (expected %.12f)%s\n", what, got, want, ok ? "" : "  WRONG");
    failures += !ok;
}

static const char *URDF =
    "<robot name=\"arm\"><link name=\"base\"/>"
    "<link name=\"rod\"><collision><origin xyz=\"0.5 0 0\"/>"
    "<geometry><box size=\"1 0.1 0.1\"/></geometry></collision></link>"
    "<joint name=\"j\" type=\"revolute\"><parent link=\"base\"/><child link=\"rod\"/>"
    "<axis xyz=\"0 0 1\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/>"
    "</joint></robot>";

int main(int argc, char **argv) {
    const char *service = argc > 1 ? argv[1] : "gjkd";
    gjkd_client *c = NULL;
    check(gjkd_connect(service, 1.0, 10.0, &c), "gjkd_connect");

    gjkd_robot *robot = NULL;
    check(gjkd_register_robot_text(c, "arm", URDF, NULL, NULL, NULL, NULL, &robot),
          "gjkd_register_robot_text");
    gjkd_id robot_id, rod, ball;
    check(gjkd_robot_info(robot, &robot_id, NULL, NULL), "gjkd_robot_info");
    check(gjkd_robot_link_id(robot, "rod", &rod), "gjkd_robot_link_id");
    gjkd_pose beside = {{0.8, 0.5, 0.0}, {0.0, 0.0, 0.0, 1.0}};
    check(gjkd_register_sphere(c, 0.1, NULL, &beside, &ball), "gjkd_register_sphere");

    /* One pair, its gradient with respect to the joint. */
    gjkd_pair_query row = gjkd_pair_query_of(rod, ball, NULL);
    row.flags |= GJKD_PAIR_GRADIENT; /* | GJKD_PAIR_GRADIENT_BASE */
    gjkd_result result;
    gjkd_gradient gradient; /* one per row that asks; keep it from call to call */
    size_t gradients = 0;
    check(gjkd_query_pairs_gradients(c, &row, 1, &result, &gradient, 1, &gradients),
          "gjkd_query_pairs_gradients");
    expect("rod-ball distance", result.distance, 0.35);
    expect("d distance / d j", gradient.values[0], -0.8);
    printf("pair columns           %u\n", gradient.columns);
    failures += gradients != 1;
    failures += gradient.columns != 1;
    failures += !(gradient.flags & GJKD_GRADIENT_PRESENT);
    failures += (gradient.flags & GJKD_GRADIENT_NOT_UNIQUE) != 0;
    /* Without a gradient array the row is refused, nothing sent. */
    failures += gjkd_query_pairs(c, &row, 1, &result) != GJKD_ERR_INVALID_ARGUMENT;

    /* Every pair within 1 m, each row with its gradient. */
    gjkd_scene_options options = gjkd_scene_options_default();
    options.gradients = true;
    gjkd_group group = {robot_id, NULL, 0, NULL, 0};
    gjkd_scene_row rows[8];
    gjkd_scene_summary summary;
    check(gjkd_within(c, &group, 1.0, &options, rows, 8, &summary), "gjkd_within");
    printf("rows                   %zu\n", summary.written);
    failures += summary.written != 1;
    expect("row d distance / d j", rows[0].gradient.values[0], -0.8);

    check(gjkd_remove(c, ball), "gjkd_remove");
    check(gjkd_robot_free(robot), "gjkd_robot_free");
    check(gjkd_close(c), "gjkd_close");
    printf(failures ? "FAILED (%d)\n" : "ok\n", failures);
    return failures ? 1 : 0;
}
