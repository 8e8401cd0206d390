/*
 * A C renderer's view of het-bssrdf: prepare a material, estimate the homogeneous
 * coefficients of one pair of points over the renderer's own surface and texture (here the
 * plane z = 0 with a checkerboard of two media), and evaluate the separable BSSRDF S there.
 * Prints S and its bits; `cargo run -p het-bssrdf-capi --example pair` prints the same from
 * Rust, and .ci/run checks that the bits agree.
 *
 * Build (from the repository root, after `cargo build --release -p het-bssrdf-capi`):
 *   gcc -std=c11 -O2 -ffp-contract=off -Icrates/capi/include crates/capi/examples/pair.c \
 *       target/release/libhet_bssrdf_capi.a -lm -lpthread -ldl -o pair
 */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "het_bssrdf.h"

/* The checkerboard's cell size and its two media (1/length, per channel). */
#define CELL 0.5
static const HbCoefficients MEDIA[2] = {
    {{0.02, 0.05, 0.1}, {1.0, 1.0, 1.0}},
    {{0.3, 0.4, 0.6}, {2.0, 2.0, 2.0}},
};

/* The plane z = 0 (the medium below, normal +z): where the line origin + t dir meets it. */
static bool project(void *user, const double *o, const double *d, HbSurfacePoint *out) {
    (void)user;
    if (fabs(d[2]) < 1e-12) {
        return false;
    }
    double t = -o[2] / d[2];
    double x = o[0] + t * d[0], y = o[1] + t * d[1];
    if (!isfinite(x) || !isfinite(y)) {
        return false;
    }
    *out = (HbSurfacePoint){{x, y, 0.0}, {0.0, 0.0, 1.0}, 0};
    return true;
}

/* The checkerboard: medium 0 in the cell holding the origin. */
static void coefficients(void *user, const HbSurfacePoint *p, HbCoefficients *out) {
    (void)user;
    int64_t cells = (int64_t)floor(p->position[0] / CELL) + (int64_t)floor(p->position[1] / CELL);
    *out = MEDIA[cells & 1];
}

static uint64_t bits(double v) {
    uint64_t b;
    memcpy(&b, &v, sizeof b);
    return b;
}

static int fail(const char *what) {
    fprintf(stderr, "%s: %s\n", what, hb_last_error());
    return 1;
}

int main(void) {
    HbMaterial *material = NULL;
    if (hb_material_new("tabulated", "all", "sone", 0.0, 1.3, &material) != HB_STATUS_OK) {
        return fail("hb_material_new");
    }
    HbSurface surface = {NULL, project, coefficients};
    HbSurfacePoint x_i = {{0.1, 0.2, 0.0}, {0.0, 0.0, 1.0}, 0};
    HbSurfacePoint x_o = {{0.7, -0.3, 0.0}, {0.0, 0.0, 1.0}, 0};
    HbCoefficients c;
    if (hb_estimate(material, &surface, &x_i, &x_o, 7, &c) != HB_STATUS_OK) {
        return fail("hb_estimate");
    }
    HbCrossing in = {{0.1, 0.2, 0.0}, {0.0, 0.0, 1.0}, {0.6, 0.0, 0.8}};
    HbCrossing out = {{0.7, -0.3, 0.0}, {0.0, 0.0, 1.0}, {0.0, 0.28, 0.96}};
    double s[3];
    if (hb_eval(material, &c, &in, &out, s) != HB_STATUS_OK) {
        return fail("hb_eval");
    }
    printf("sigma_a = %.6g %.6g %.6g, sigma_s = %.6g %.6g %.6g\n", c.sigma_a[0], c.sigma_a[1],
           c.sigma_a[2], c.sigma_s[0], c.sigma_s[1], c.sigma_s[2]);
    printf("S = %.6e %.6e %.6e (1/(length^2 sr))\n", s[0], s[1], s[2]);
    printf("bits %016" PRIx64 " %016" PRIx64 " %016" PRIx64 "\n", bits(s[0]), bits(s[1]),
           bits(s[2]));
    /* A typed error, not a crash: η outside [1, 3]. */
    HbMaterial *bad = NULL;
    if (hb_material_new("dipole", "all", "sone", 0.0, 0.5, &bad) == HB_STATUS_INVALID_ARGUMENT) {
        printf("refused: %s\n", hb_last_error());
    }
    hb_material_free(material);
    return 0;
}
