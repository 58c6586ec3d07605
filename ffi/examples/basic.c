/*
 * basic.c: connect to a gjkd server, register shapes, store their poses,
 * ask the distances of a batch of pairs and one pair, and check them
 * against their analytic values.
 *
 *   gjkd serve &                  # in another terminal
 *   cc -std=c99 basic.c -I ffi/include -L target/release -lgjkd_c -o basic
 *   LD_LIBRARY_PATH=target/release ./basic [SERVICE]
 *
 * Exits 0 when every answer is within 1e-9 of the analytic one.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "gjkd.h"

static int failures = 0;

/* Prints the failed call's status and message, and leaves. */
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

static gjkd_pose at(double x, double y, double z) {
    gjkd_pose p = {{x, y, z}, {0.0, 0.0, 0.0, 1.0}};
    return p;
}

int main(int argc, char **argv) {
    const char *service = argc > 1 ? argv[1] : "gjkd";
    gjkd_client *client = NULL;
    check(gjkd_connect(service, 1.0, 10.0, &client), "gjkd_connect");

    /* Shapes, registered once; a box under a name others can look up. */
    const double half[3] = {1.0, 1.0, 1.0};
    const double end_a[3] = {0.0, -1.0, 0.0}, end_b[3] = {0.0, 1.0, 0.0};
    const double cube[8 * 3] = {-.5, -.5, -.5, .5, -.5, -.5, -.5, .5, -.5, .5, .5, -.5,
                                -.5, -.5, .5,  .5, -.5, .5,  -.5, .5, .5,  .5, .5, .5};
    gjkd_id box, ball, rod, block, dumbbell, found;
    check(gjkd_register_box(client, half, 0.0, "basic-box", NULL, &box), "register box");
    check(gjkd_register_sphere(client, 0.5, NULL, NULL, &ball), "register sphere");
    check(gjkd_register_capsule(client, end_a, end_b, 0.25, NULL, NULL, &rod),
          "register capsule");
    check(gjkd_register_polytope(client, cube, 8, 0.0, NULL, NULL, &block),
          "register polytope");
    gjkd_shape bead = {GJKD_SHAPE_SPHERE, 0.3, {0, 0, 0}, {0, 0, 0}, NULL, 0};
    gjkd_piece pieces[2] = {{at(-1.0, 0.0, 0.0), bead}, {at(1.0, 0.0, 0.0), bead}};
    check(gjkd_register_compound(client, pieces, 2, NULL, NULL, &dumbbell),
          "register compound");
    check(gjkd_lookup(client, "basic-box", &found), "gjkd_lookup");
    printf("box id %#llx, found by name: %s\n", (unsigned long long)box,
           found == box ? "yes" : "NO");
    failures += found != box;

    /* Poses, stored by the server, all in one round trip. */
    gjkd_id moved[4] = {ball, rod, block, dumbbell};
    gjkd_pose poses[4] = {at(3, 0, 0), at(0, 5, 0), at(-4, 0, 0), at(0, -5, 0)};
    check(gjkd_set_poses(client, moved, poses, 4), "gjkd_set_poses");

    /* A batch of pairs into arrays this program owns. The last pair names
     * an id no server gave out: it fails alone, with its own code. */
    enum { N = 6 };
    gjkd_id pairs[2 * N] = {box, ball, box, rod, box, block,
                            ball, rod, box, dumbbell, box, 0xdead};
    double distance[N], lower[N], upper[N], point_a[3 * N], point_b[3 * N];
    uint32_t status[N], error[N];
    gjkd_results out = {0};
    out.distance = distance;
    out.lower = lower;
    out.upper = upper;
    out.point_a = point_a;
    out.point_b = point_b;
    out.status = status;
    out.error = error;
    check(gjkd_distances(client, pairs, N, NULL, NULL, NULL, &out), "gjkd_distances");

    const double want[N - 1] = {1.5, 2.75, 2.5, 4.25, 3.7};
    const char *names[N - 1] = {"box-sphere", "box-capsule", "box-polytope",
                                "sphere-capsule", "box-compound"};
    for (int i = 0; i < N - 1; i++) {
        if (error[i] != GJKD_CODE_OK) {
            printf("%s: %s\n", names[i], gjkd_error_code_describe(error[i]));
            failures++;
            continue;
        }
        expect(names[i], distance[i], want[i]);
        failures += !(lower[i] <= distance[i] && distance[i] <= upper[i]);
        failures += status[i] != GJKD_QUERY_CONVERGED;
    }
    printf("box-sphere points      (%g, %g, %g) (%g, %g, %g)\n", point_a[0], point_a[1],
           point_a[2], point_b[0], point_b[1], point_b[2]);
    expect("box-sphere point_a.x", point_a[0], 1.0);
    expect("box-sphere point_b.x", point_b[0], 2.5);
    printf("unknown pair           %s (%s)\n", gjkd_error_code_name(error[N - 1]),
           gjkd_error_code_describe(error[N - 1]));
    failures += error[N - 1] != GJKD_CODE_UNKNOWN_OBJECT;

    /* One pair at poses given for this query only. */
    gjkd_pose above = at(0, 0, 4);
    gjkd_answer answer;
    check(gjkd_distance(client, box, ball, NULL, &above, NULL, &answer), "gjkd_distance");
    expect("box-sphere above", answer.distance, 2.5);

    /* A refused call: its status, the server's code and the words. */
    gjkd_status s = gjkd_lookup(client, "no-such-object", &found);
    printf("lookup of a missing name: %s, %s: %s\n", gjkd_status_name(s),
           gjkd_error_code_name(gjkd_last_error_code()), gjkd_last_error());
    failures += s != GJKD_ERR_REJECTED || gjkd_last_error_code() != GJKD_CODE_UNKNOWN_NAME;

    gjkd_id all[5] = {box, ball, rod, block, dumbbell};
    for (int i = 0; i < 5; i++) check(gjkd_remove(client, all[i]), "gjkd_remove");
    check(gjkd_close(client), "gjkd_close");
    printf(failures ? "FAILED (%d)\n" : "ok\n", failures);
    return failures ? 1 : 0;
}
