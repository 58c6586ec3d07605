/*
 * round_trip.c: the C side of `cargo run --release -p gjkd-c --example
 * bench_c_vs_rust`, which writes the pairs, starts the server and runs
 * this program between its own Rust measurements.
 *
 *   round_trip SERVICE PAIRS_FILE SINGLES BATCHES
 *
 * PAIRS_FILE holds n (as a double), then per pair the half extents of A
 * and B (6 doubles) and the poses of A and B (7 doubles each, [x, y, z,
 * qx, qy, qz, qw]), little-endian. Prints
 *   single_p50_ns X     (gjkd_distance of pair 0 at stored poses)
 *   batch_ns_per_pair Y (median over BATCHES of gjkd_distances of all n
 *                        pairs, each with its own poses, divided by n)
 *   rows_ns_per_pair Z  (the same through gjkd_query_pairs: a
 *                        gjkd_pair_query row per pair in, a gjkd_result
 *                        row out)
 */
#define _POSIX_C_SOURCE 199309L /* clock_gettime under -std=c99 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "gjkd.h"

static void must(gjkd_status s, const char *what) {
    if (s != GJKD_OK) {
        fprintf(stderr, "%s: %s\n", what, gjkd_last_error());
        exit(2);
    }
}

static double now_ns(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e9 + (double)t.tv_nsec;
}

static int by_value(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, size_t n) {
    qsort(v, n, sizeof *v, by_value);
    return v[n / 2];
}

int main(int argc, char **argv) {
    if (argc < 5) {
        fprintf(stderr, "usage: round_trip SERVICE PAIRS_FILE SINGLES BATCHES\n");
        return 2;
    }
    size_t singles = (size_t)atol(argv[3]), batches = (size_t)atol(argv[4]);
    FILE *f = fopen(argv[2], "rb");
    double head;
    if (!f || fread(&head, sizeof head, 1, f) != 1) return 2;
    size_t n = (size_t)head;
    double *rows = malloc(n * 20 * sizeof *rows);
    if (fread(rows, sizeof *rows, n * 20, f) != n * 20) return 2;
    fclose(f);

    gjkd_client *c = NULL;
    must(gjkd_connect(argv[1], 5.0, 20.0, &c), "connect");
    gjkd_id *pairs = malloc(2 * n * sizeof *pairs);
    gjkd_pose *poses_a = malloc(n * sizeof *poses_a), *poses_b = malloc(n * sizeof *poses_b);
    for (size_t i = 0; i < n; i++) {
        const double *r = rows + 20 * i;
        must(gjkd_register_box(c, r, 0.0, NULL, NULL, &pairs[2 * i]), "register");
        must(gjkd_register_box(c, r + 3, 0.0, NULL, NULL, &pairs[2 * i + 1]), "register");
        memcpy(&poses_a[i], r + 6, sizeof(gjkd_pose));
        memcpy(&poses_b[i], r + 13, sizeof(gjkd_pose));
    }
    must(gjkd_set_poses(c, pairs, poses_a, 1), "set pose a");
    must(gjkd_set_poses(c, pairs + 1, poses_b, 1), "set pose b");

    gjkd_answer answer;
    double *t = malloc((singles > batches ? singles : batches) * sizeof *t);
    for (size_t k = 0; k < singles / 10 + 100; k++) {
        must(gjkd_distance(c, pairs[0], pairs[1], NULL, NULL, NULL, &answer), "warm-up");
    }
    for (size_t k = 0; k < singles; k++) {
        double start = now_ns();
        gjkd_status s = gjkd_distance(c, pairs[0], pairs[1], NULL, NULL, NULL, &answer);
        t[k] = now_ns() - start;
        must(s, "distance");
    }
    printf("single_p50_ns %.1f\n", median(t, singles));

    double *distance = malloc(n * sizeof(double)), *lower = malloc(n * sizeof(double)),
           *upper = malloc(n * sizeof(double)), *point_a = malloc(3 * n * sizeof(double)),
           *point_b = malloc(3 * n * sizeof(double)), *normal = malloc(3 * n * sizeof(double));
    uint32_t *status = malloc(n * sizeof(uint32_t)), *error = malloc(n * sizeof(uint32_t)),
             *iterations = malloc(n * sizeof(uint32_t));
    gjkd_results out;
    memset(&out, 0, sizeof out);
    out.distance = distance;
    out.lower = lower;
    out.upper = upper;
    out.point_a = point_a;
    out.point_b = point_b;
    out.normal = normal;
    out.status = status;
    out.iterations = iterations;
    out.error = error;
    for (size_t k = 0; k < 20; k++) {
        must(gjkd_distances(c, pairs, n, poses_a, poses_b, NULL, &out), "warm-up batch");
    }
    for (size_t k = 0; k < batches; k++) {
        double start = now_ns();
        gjkd_status s = gjkd_distances(c, pairs, n, poses_a, poses_b, NULL, &out);
        t[k] = (now_ns() - start) / (double)n;
        must(s, "distances");
    }
    printf("batch_ns_per_pair %.1f\n", median(t, batches));

    gjkd_pair_query *queries = malloc(n * sizeof *queries);
    gjkd_result *results = malloc(n * sizeof *results);
    for (size_t i = 0; i < n; i++) {
        queries[i] = gjkd_pair_query_of(pairs[2 * i], pairs[2 * i + 1], NULL);
        queries[i].pose_a = poses_a[i];
        queries[i].pose_b = poses_b[i];
        queries[i].flags |= GJKD_POSE_A | GJKD_POSE_B;
    }
    for (size_t k = 0; k < 20; k++) {
        must(gjkd_query_pairs(c, queries, n, results), "warm-up rows");
    }
    for (size_t k = 0; k < batches; k++) {
        double start = now_ns();
        gjkd_status s = gjkd_query_pairs(c, queries, n, results);
        t[k] = (now_ns() - start) / (double)n;
        must(s, "query_pairs");
    }
    printf("rows_ns_per_pair %.1f\n", median(t, batches));
    printf("checksum %.17g %.17g\n", distance[n - 1], results[n - 1].distance);

    for (size_t i = 0; i < 2 * n; i++) must(gjkd_remove(c, pairs[i]), "remove");
    must(gjkd_close(c), "close");
    return 0;
}
