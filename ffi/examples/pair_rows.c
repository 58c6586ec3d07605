/*
 * pair_rows.c: the fastest batch of the C API. Each pair is a
 * gjkd_pair_query row (ids, and poses for this query only), each answer a
 * gjkd_result row; the rows are kept and reused, only the poses that move
 * are rewritten between calls. Checks every answer against its analytic
 * value.
 *
 *   gjkd serve &                  # in another terminal
 *   cc -std=c99 pair_rows.c -I ffi/include -L target/release -lgjkd_c -o pair_rows
 *   LD_LIBRARY_PATH=target/release ./pair_rows [SERVICE]
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

    /* A unit box at the origin (stored pose), a ball, a rod along y. */
    const double half[3] = {1.0, 1.0, 1.0};
    const double end_a[3] = {0.0, -1.0, 0.0}, end_b[3] = {0.0, 1.0, 0.0};
    gjkd_id box, ball, rod;
    check(gjkd_register_box(client, half, 0.0, NULL, NULL, &box), "register box");
    check(gjkd_register_sphere(client, 0.5, NULL, NULL, &ball), "register sphere");
    check(gjkd_register_capsule(client, end_a, end_b, 0.25, NULL, NULL, &rod),
          "register capsule");

    /* The rows, built once. Start from gjkd_pair_query_of(, NULL) (stored poses),
     * then give a pose and set its bit where this query has its own. */
    enum { N = 5 };
    gjkd_pair_query rows[N];
    rows[0] = gjkd_pair_query_of(box, ball, NULL); /* ball at x = 3 */
    rows[0].pose_b = at(3, 0, 0);
    rows[0].flags |= GJKD_POSE_B;
    rows[1] = gjkd_pair_query_of(box, ball, NULL); /* both given: box lifted to z = 10 */
    rows[1].pose_a = at(0, 0, 10);
    rows[1].pose_b = at(0, 0, 0);
    rows[1].flags |= GJKD_POSE_A | GJKD_POSE_B;
    rows[2] = gjkd_pair_query_of(box, rod, NULL); /* rod at y = 5 */
    rows[2].pose_b = at(0, 5, 0);
    rows[2].flags |= GJKD_POSE_B;
    rows[3] = gjkd_pair_query_of(ball, rod, NULL); /* ball at x = -4, rod at the origin */
    rows[3].pose_a = at(-4, 0, 0);
    rows[3].pose_b = at(0, 0, 0);
    rows[3].flags |= GJKD_POSE_A | GJKD_POSE_B;
    rows[4] = gjkd_pair_query_of(box, 0xdead, NULL); /* an id no server gave out */

    gjkd_result out[N];
    check(gjkd_query_pairs(client, rows, N, out), "gjkd_query_pairs");
    const double want[N - 1] = {1.5, 8.5, 2.75, 3.25};
    const char *names[N - 1] = {"box-sphere", "box lifted-sphere", "box-capsule",
                                "sphere-capsule"};
    for (int i = 0; i < N - 1; i++) {
        if (out[i].error != GJKD_CODE_OK) {
            printf("%s: %s\n", names[i], gjkd_error_code_describe(out[i].error));
            failures++;
            continue;
        }
        expect(names[i], out[i].distance, want[i]);
        failures += !(out[i].lower <= out[i].distance && out[i].distance <= out[i].upper);
        failures += out[i].status != GJKD_QUERY_CONVERGED;
    }
    expect("box-sphere point_a.x", out[0].point_a[0], 1.0);
    expect("box-sphere point_b.x", out[0].point_b[0], 2.5);
    expect("box-sphere normal.x", out[0].normal[0], 1.0);
    printf("unknown pair           %s\n", gjkd_error_code_name(out[N - 1].error));
    failures += out[N - 1].error != GJKD_CODE_UNKNOWN_OBJECT;

    /* A motion: the same rows again, only the ball's pose rewritten. The
     * second and later steps start warm from the pair's last simplex. */
    for (int step = 1; step <= 3; step++) {
        rows[0].pose_b.translation[0] = 3.0 + step;
        check(gjkd_query_pairs(client, rows, 1, out), "gjkd_query_pairs");
        char what[32];
        snprintf(what, sizeof what, "ball at x = %d", 3 + step);
        expect(what, out[0].distance, 1.5 + step);
    }
    printf("warm started           %s\n",
           out[0].flags & GJKD_RESULT_WARM_STARTED ? "yes" : "no");

    /* A row with bits the API does not define is refused, nothing sent. */
    rows[0].flags |= 1u << 5;
    gjkd_status s = gjkd_query_pairs(client, rows, N, out);
    printf("undefined pose bit: %s: %s\n", gjkd_status_name(s), gjkd_last_error());
    failures += s != GJKD_ERR_INVALID_ARGUMENT;

    gjkd_id all[3] = {box, ball, rod};
    for (int i = 0; i < 3; i++) check(gjkd_remove(client, all[i]), "gjkd_remove");
    check(gjkd_close(client), "gjkd_close");
    printf(failures ? "FAILED (%d)\n" : "ok\n", failures);
    return failures ? 1 : 0;
}
