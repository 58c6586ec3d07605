/*
 * signed_distance.c: how deep two objects overlap, through the C API. A
 * pair query asked with gjkd_query_options::signed_distance answers the
 * signed distance (the distance apart, minus the penetration depth
 * overlapping) with a certified interval, and its witnesses and normal;
 * the same rows of gjkd_query_pairs carry it in gjkd_result. Checks every
 * answer against its analytic value.
 *
 *   gjkd serve &                  # in another terminal
 *   cc -std=c99 signed_distance.c -I ffi/include -L target/release -lgjkd_c -o signed_distance
 *   LD_LIBRARY_PATH=target/release ./signed_distance [SERVICE]
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

static void expect_true(const char *what, int ok) {
    printf("%-22s %s%s\n", what, ok ? "yes" : "no", ok ? "" : "  WRONG");
    failures += !ok;
}

int main(int argc, char **argv) {
    const char *service = argc > 1 ? argv[1] : "gjkd";
    gjkd_client *c = NULL;
    check(gjkd_connect(service, 1.0, 10.0, &c), "gjkd_connect");

    /* A unit box at the origin, a ball of radius 0.5 0.7 deep into its face
     * x = 1, and a ball apart from it. */
    const double half[3] = {1.0, 1.0, 1.0};
    gjkd_pose inside = {{0.8, 0.0, 0.0}, {0.0, 0.0, 0.0, 1.0}};
    gjkd_pose apart = {{0.0, 3.0, 0.0}, {0.0, 0.0, 0.0, 1.0}};
    gjkd_id box, ball, far;
    check(gjkd_register_box(c, half, 0.0, NULL, NULL, &box), "register box");
    check(gjkd_register_sphere(c, 0.5, NULL, &inside, &ball), "register ball");
    check(gjkd_register_sphere(c, 0.5, NULL, &apart, &far), "register far ball");

    gjkd_query_options o = gjkd_query_options_default();
    o.signed_distance = true;
    gjkd_answer a;
    check(gjkd_distance(c, box, ball, NULL, NULL, &o, &a), "gjkd_distance");
    expect_true("signed answered", a.has_signed_distance);
    expect("signed box-ball", a.signed_distance, -0.7);
    expect_true("interval holds -0.7", a.signed_lower <= -0.7 && -0.7 <= a.signed_upper);
    expect("normal.x", a.normal[0], 1.0);
    expect("point_b - point_a", a.point_b[0] - a.point_a[0], -0.7);

    /* Apart, the signed distance is the distance. */
    check(gjkd_distance(c, box, far, NULL, NULL, &o, &a), "gjkd_distance apart");
    expect("signed box-far ball", a.signed_distance, 1.5);

    /* Off by default. */
    check(gjkd_distance(c, box, ball, NULL, NULL, NULL, &a), "gjkd_distance default");
    expect_true("default has none", !a.has_signed_distance);

    /* The same in rows: the option travels in the row's flags. */
    gjkd_pair_query row = gjkd_pair_query_of(box, ball, &o);
    gjkd_result r;
    check(gjkd_query_pairs(c, &row, 1, &r), "gjkd_query_pairs");
    expect_true("row flagged", (r.flags & GJKD_RESULT_SIGNED_DISTANCE) != 0);
    expect("row signed box-ball", r.signed_distance, -0.7);

    gjkd_close(c);
    printf("%s\n", failures ? "FAILED" : "ok");
    return failures ? 1 : 0;
}
