/*
 * api_checks.c: what the header promises, checked call by call: poses
 * held to the server's limit when set, one status and code per fault,
 * robots removed whole, names reused and objects ended with their handle,
 * a handle used and closed on another thread, empty batches and groups.
 * Argument: SERVICE. Prints one line per check and "ok" last when all
 * held.
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gjkd.h"

static int failures = 0;

static const char *URDF =
    "<robot name=\"arm\"><link name=\"base\"><collision><geometry>"
    "<box size=\"0.2 0.2 0.2\"/></geometry></collision></link>"
    "<link name=\"tip\"><collision><origin xyz=\"1 0 0\"/><geometry><sphere radius=\"0.1\"/>"
    "</geometry></collision></link>"
    "<joint name=\"turn\" type=\"revolute\"><parent link=\"base\"/><child link=\"tip\"/>"
    "<axis xyz=\"0 0 1\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/>"
    "</joint></robot>";

static void must(gjkd_status s, const char *what) {
    if (s != GJKD_OK) {
        fprintf(stderr, "%s: %s %s\n", what, gjkd_status_name(s), gjkd_last_error());
        exit(2);
    }
}

/* `s` must be `status` with last error code `code` (a success leaves the
 * last error as it was: only the status counts then). */
static void expect_error(const char *what, gjkd_status s, gjkd_status status, uint32_t code) {
    int ok = s == status && (s == GJKD_OK || gjkd_last_error_code() == code);
    printf("%-40s %s %s%s\n", what, gjkd_status_name(s),
           s == GJKD_OK ? "" : gjkd_error_code_name(gjkd_last_error_code()), ok ? "" : "  WRONG");
    failures += !ok;
}

static void expect(const char *what, double got, double want) {
    int ok = fabs(got - want) <= 1e-9 * (1 + fabs(want));
    printf("%-40s %.12g (expected %.12g)%s\n", what, got, want, ok ? "" : "  WRONG");
    failures += !ok;
}

static gjkd_pose at(double x, double y, double z) {
    gjkd_pose p = {{x, y, z}, {0, 0, 0, 1}};
    return p;
}

static double dist(gjkd_client *c, gjkd_id a, gjkd_id b) {
    gjkd_answer ans;
    must(gjkd_distance(c, a, b, NULL, NULL, NULL, &ans), "distance");
    return ans.distance;
}

/* Uses a handle made on the main thread, then closes it, here. */
struct borrowed {
    gjkd_client *client;
    gjkd_id a, b;
    double distance;
    gjkd_status closed;
};

static void *use_and_close(void *arg) {
    struct borrowed *job = arg;
    job->distance = dist(job->client, job->a, job->b);
    job->closed = gjkd_close(job->client);
    return NULL;
}

int main(int argc, char **argv) {
    if (argc < 2) {
        fprintf(stderr, "usage: api_checks SERVICE\n");
        return 2;
    }
    const char *service = argv[1];
    gjkd_client *c = NULL;
    must(gjkd_connect(service, 2.0, 10.0, &c), "connect");
    gjkd_id a = 0, b = 0;
    gjkd_pose origin = at(0, 0, 0), far = at(5, 0, 0);
    must(gjkd_register_sphere(c, 1.0, NULL, &origin, &a), "register a");
    must(gjkd_register_sphere(c, 1.0, NULL, &far, &b), "register b");

    /* Poses: held to the server's limit when set; one fault, one class. */
    gjkd_pose huge = at(1e305, 0, 0), nan_pose = at(NAN, 0, 0);
    gjkd_answer ans;
    expect_error("set_pose 1e305", gjkd_set_pose(c, a, &huge), GJKD_ERR_INVALID_ARGUMENT,
                 GJKD_CODE_NON_FINITE_POSE);
    expect_error("set_pose NaN", gjkd_set_pose(c, a, &nan_pose), GJKD_ERR_INVALID_ARGUMENT,
                 GJKD_CODE_NON_FINITE_POSE);
    expect_error("distance at NaN", gjkd_distance(c, a, b, &nan_pose, NULL, NULL, &ans),
                 GJKD_ERR_INVALID_ARGUMENT, GJKD_CODE_NON_FINITE_POSE);
    expect("nothing stored", dist(c, a, b), 3.0);
    gjkd_pose edge = at(GJKD_MAX_TRANSLATION, 0, 0), other_edge = at(-GJKD_MAX_TRANSLATION, 0, 0);
    must(gjkd_set_pose(c, a, &edge), "set_pose at the limit");
    must(gjkd_set_pose(c, b, &other_edge), "set_pose at the other limit");
    expect("answered at the limits", dist(c, a, b), 2 * GJKD_MAX_TRANSLATION);
    must(gjkd_set_pose(c, a, &origin), "set_pose back");
    must(gjkd_set_pose(c, b, &far), "set_pose back");

    /* A count of 0 does nothing, whatever is NULL. */
    expect_error("distances of no pair", gjkd_distances(c, NULL, 0, NULL, NULL, NULL, NULL),
                 GJKD_OK, GJKD_CODE_OK);

    /* An empty group has no rows. */
    gjkd_group empty = {0, NULL, 0, NULL, 0};
    gjkd_scene_summary summary;
    expect_error("clearance of an empty group",
                 gjkd_clearance(c, &empty, NULL, NULL, 0, &summary), GJKD_OK, GJKD_CODE_OK);
    expect("  its rows", (double)(summary.written + summary.total), 0.0);
    expect_error("within of an empty group",
                 gjkd_within(c, &empty, 1.0, NULL, NULL, 0, &summary), GJKD_OK, GJKD_CODE_OK);

    /* Robots: local look-ups are no refusals; the robot id is no object
     * id; a robot is removed whole. */
    gjkd_robot *robot = NULL;
    must(gjkd_register_robot_text(c, "api-arm", URDF, NULL, NULL, NULL, NULL, &robot), "robot");
    gjkd_id robot_id = 0, tip = 0;
    must(gjkd_robot_info(robot, &robot_id, NULL, NULL), "robot_info");
    must(gjkd_robot_link_id(robot, "tip", &tip), "tip");
    double nan_joint = NAN;
    expect_error("NaN joint", gjkd_set_joints(c, robot, &nan_joint, 1, NULL, false),
                 GJKD_ERR_INVALID_ARGUMENT, GJKD_CODE_NON_FINITE_POSE);
    gjkd_id none = 0;
    expect_error("link_id of no link", gjkd_robot_link_id(robot, "nope", &none),
                 GJKD_ERR_INVALID_ARGUMENT, GJKD_CODE_UNKNOWN_NAME);
    expect_error("remove(robot id)", gjkd_remove(c, robot_id), GJKD_ERR_REJECTED,
                 GJKD_CODE_UNKNOWN_OBJECT);
    expect("tip to b", dist(c, tip, b), 2.9);
    expect_error("remove_robot", gjkd_remove_robot(c, robot), GJKD_OK, GJKD_CODE_OK);
    expect_error("  its link gone", gjkd_distance(c, tip, b, NULL, NULL, NULL, &ans),
                 GJKD_ERR_REJECTED, GJKD_CODE_UNKNOWN_OBJECT);
    expect_error("  the robot gone", gjkd_remove_robot(c, robot), GJKD_ERR_REJECTED,
                 GJKD_CODE_UNKNOWN_NAME);
    must(gjkd_robot_free(robot), "robot_free");

    /* Names reused by a restarted node; objects ended with their handle. */
    gjkd_id named = 0, again = 0;
    must(gjkd_register_sphere(c, 0.5, "api-named", NULL, &named), "named");
    expect_error("name taken", gjkd_register_sphere(c, 0.5, "api-named", NULL, &again),
                 GJKD_ERR_REJECTED, GJKD_CODE_NAME_TAKEN);
    gjkd_client *restarted = NULL;
    must(gjkd_connect(service, 2.0, 0.0, &restarted), "connect again");
    gjkd_registration_options reuse = {true, false};
    must(gjkd_set_registration_options(restarted, &reuse), "reuse names");
    must(gjkd_register_sphere(restarted, 0.5, "api-named", NULL, &again), "register-or-get");
    expect("register-or-get gives the id", (double)(again == named), 1.0);
    gjkd_registration_options scratch = {false, true};
    must(gjkd_set_registration_options(restarted, &scratch), "end with the handle");
    gjkd_id temp = 0;
    must(gjkd_register_sphere(restarted, 0.5, "api-temporary", NULL, &temp), "temporary");
    gjkd_robot *temp_robot = NULL;
    must(gjkd_register_robot_text(restarted, "api-temp-arm", URDF, NULL, NULL, NULL, NULL,
                                  &temp_robot),
         "temporary robot");
    must(gjkd_robot_free(temp_robot), "robot_free");

    /* Used and closed on another thread. */
    struct borrowed job = {restarted, a, b, 0.0, GJKD_ERR_PANIC};
    pthread_t thread;
    if (pthread_create(&thread, NULL, use_and_close, &job) != 0 || pthread_join(thread, NULL)) {
        fprintf(stderr, "no thread\n");
        return 2;
    }
    expect("distance on another thread", job.distance, 3.0);
    expect_error("closed on another thread", job.closed, GJKD_OK, GJKD_CODE_OK);
    gjkd_id gone = 0;
    expect_error("  its temporary object gone", gjkd_lookup(c, "api-temporary", &gone),
                 GJKD_ERR_REJECTED, GJKD_CODE_UNKNOWN_NAME);
    expect_error("  its temporary robot gone", gjkd_lookup(c, "api-temp-arm/tip", &gone),
                 GJKD_ERR_REJECTED, GJKD_CODE_UNKNOWN_NAME);
    printf("%-40s %s\n", "busy status", gjkd_status_name(GJKD_ERR_BUSY));
    failures += strcmp(gjkd_status_name(GJKD_ERR_BUSY), "GJKD_ERR_BUSY") != 0;

    must(gjkd_remove(c, named), "remove");
    must(gjkd_remove(c, a), "remove");
    must(gjkd_remove(c, b), "remove");
    must(gjkd_close(c), "close");
    printf(failures ? "FAILED (%d)\n" : "ok\n", failures);
    return failures ? 1 : 0;
}
