/*
 * leak_check.c: many calls of the C API, failing and succeeding, for
 * valgrind to check that nothing leaks. Arguments: SERVICE CALLS.
 *
 * Most calls fail before reaching the server (each failure builds a new
 * last-error message and frees the old one); one in ROUND_TRIP_EVERY is a
 * round trip (a set_poses batch, a distances and a query_pairs batch, a
 * failed lookup, a robot's joints set), and a few client and robot handles are opened and
 * closed.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gjkd.h"

enum { BATCH = 16, ROUND_TRIP_EVERY = 100, HANDLES = 3 };

/* One revolute joint between a box and an exact cylinder. */
static const char *URDF =
    "<robot name=\"leaky\"><link name=\"a\"><collision><geometry>"
    "<box size=\"1 1 1\"/></geometry></collision></link>"
    "<link name=\"b\"><collision><geometry><cylinder radius=\"0.1\" length=\"1\"/>"
    "</geometry></collision></link>"
    "<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>"
    "<axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>"
    "</joint></robot>";

static void must(gjkd_status s, const char *what) {
    if (s != GJKD_OK) {
        fprintf(stderr, "%s: %s\n", what, gjkd_last_error());
        exit(2);
    }
}

static void must_fail(gjkd_status s, gjkd_status want, const char *what) {
    if (s != want || gjkd_last_error()[0] == '\0') {
        fprintf(stderr, "%s: got %s, wanted %s\n", what, gjkd_status_name(s),
                gjkd_status_name(want));
        exit(3);
    }
}

int main(int argc, char **argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: leak_check SERVICE CALLS\n");
        return 2;
    }
    const char *service = argv[1];
    long calls = atol(argv[2]);
    for (int h = 0; h < HANDLES; h++) {
        gjkd_client *extra = NULL;
        must(gjkd_connect(service, 5.0, 10.0, &extra), "connect extra");
        must(gjkd_close(extra), "close extra");
    }
    gjkd_client *c = NULL;
    must(gjkd_connect(service, 5.0, 10.0, &c), "connect");

    gjkd_id ids[BATCH], pairs[2 * BATCH];
    gjkd_pose poses[BATCH];
    for (int i = 0; i < BATCH; i++) {
        gjkd_pose p = {{3.0 * i, 0, 0}, {0, 0, 0, 1}};
        poses[i] = p;
        must(gjkd_register_sphere(c, 1.0, NULL, &poses[i], &ids[i]), "register");
    }
    for (int i = 0; i < BATCH; i++) {
        pairs[2 * i] = ids[i];
        pairs[2 * i + 1] = ids[(i + 1) % BATCH];
    }
    gjkd_pair_query rows[BATCH];
    gjkd_result results[BATCH];
    for (int i = 0; i < BATCH; i++) rows[i] = gjkd_pair_query_of(pairs[2 * i], pairs[2 * i + 1], NULL);
    gjkd_robot *robot = NULL;
    must(gjkd_register_robot_text(c, "leaky", URDF, NULL, NULL, NULL, NULL, &robot), "robot");
    for (int h = 0; h < HANDLES; h++) {
        gjkd_robot *again = NULL;
        must(gjkd_open_robot(c, "leaky", URDF, &again), "open robot");
        must(gjkd_robot_free(again), "free robot");
    }
    gjkd_pose link_poses[2];
    double q[1], far[1] = {5.0};
    double distance[BATCH], point_a[3 * BATCH];
    uint32_t error[BATCH];
    gjkd_results out;
    memset(&out, 0, sizeof out);
    out.distance = distance;
    out.point_a = point_a;
    out.error = error;

    char long_name[GJKD_MAX_NAME_LEN + 2];
    memset(long_name, 'n', sizeof long_name - 1);
    long_name[sizeof long_name - 1] = '\0';
    gjkd_pose bad = {{NAN, 0, 0}, {0, 0, 0, 1}};
    gjkd_id found;
    long round_trips = 0;
    for (long k = 0; k < calls; k++) {
        if (k % ROUND_TRIP_EVERY == 0) {
            switch ((k / ROUND_TRIP_EVERY) % 4) {
            case 3:
                q[0] = (k % 7) * 0.1;
                must(gjkd_set_joints(c, robot, q, 1, NULL, false), "set_joints");
                break;
            case 0:
                must(gjkd_set_poses(c, ids, poses, BATCH), "set_poses");
                break;
            case 1:
                must(gjkd_distances(c, pairs, BATCH, NULL, NULL, NULL, &out), "distances");
                if (fabs(distance[0] - 1.0) > 1e-9) {
                    fprintf(stderr, "distance %.17g, expected 1\n", distance[0]);
                    return 4;
                }
                must(gjkd_query_pairs(c, rows, BATCH, results), "query_pairs");
                if (fabs(results[0].distance - 1.0) > 1e-9) {
                    fprintf(stderr, "row distance %.17g, expected 1\n", results[0].distance);
                    return 4;
                }
                break;
            default:
                must_fail(gjkd_lookup(c, "absent", &found), GJKD_ERR_REJECTED, "lookup");
            }
            round_trips++;
            continue;
        }
        switch (k % 6) {
        case 5:
            must_fail(gjkd_query_pairs(c, rows, BATCH, NULL), GJKD_ERR_NULL_POINTER,
                      "null rows out");
            break;
        case 3:
            must_fail(gjkd_set_joints(c, robot, far, 1, NULL, false), GJKD_ERR_INVALID_ARGUMENT,
                      "out of limits");
            break;
        case 4:
            must(gjkd_robot_link_poses(robot, NULL, 0, NULL, false, link_poses, 2), "poses");
            break;
        case 0:
            must_fail(gjkd_lookup(c, long_name, &found), GJKD_ERR_INVALID_ARGUMENT, "long name");
            break;
        case 1:
            must_fail(gjkd_set_pose(c, ids[0], &bad), GJKD_ERR_INVALID_ARGUMENT, "nan pose");
            break;
        default:
            must_fail(gjkd_distances(c, pairs, BATCH, NULL, NULL, NULL, NULL),
                      GJKD_ERR_NULL_POINTER, "null out");
        }
    }
    must(gjkd_robot_free(robot), "free robot");
    for (int i = 0; i < BATCH; i++) must(gjkd_remove(c, ids[i]), "remove");
    must(gjkd_close(c), "close");
    printf("calls %ld, round trips %ld\n", calls, round_trips);
    return 0;
}
