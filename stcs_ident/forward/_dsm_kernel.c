/*
 * Compiled kernel of the Wittrick–Williams root solver (optional).
 *
 * The same numerics as elements.py, assembly.py and roots.py, one item
 * (configuration, mode) at a time: segment dynamic stiffness in the stable
 * exponential form, assembly on (v, θ, ĥ), scaled elimination without row
 * interchanges for the count J = J0 + s{K} − n_h and det K, bracketing by
 * the count and Anderson–Björck false position inside a pole-free
 * one-root bracket. It exists because numpy's per-call overhead dominates
 * small problems (a single configuration, or the 3×3 systems of a sweep);
 * the numpy path stays the reference and the tests compare the two.
 * The segment matrices, their assembly and J0 are shared with the complex
 * kernel (_segment.h over the scalar type, _problem.h); this file holds
 * what is its own: the attachments, the elimination and the root search.
 *
 * Arrays are C-contiguous float64 (int64 for indices), passed as buffers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <string.h>
#include <stdlib.h>
#include <stdint.h>

#define RTOL 2e-13
#define MAX_ITER 200

#include "_segment.h"

/* Count J(ω) and det of the scaled K for configuration cfg. */
static void evaluate(const Problem *P, long long cfg, double omega, int *J_out, int *J0_out, double *det_out) {
    int nd = P->n_dof;
    double K[MAX_DOF * MAX_DOF];
    int J0 = assemble(P, cfg, omega, K);
    for (int k = 0; k < P->n_att; k++) {
        long long v = P->v_dof[k + 1];
        K[v * nd + v] -= P->masses[cfg * P->n_att + k] * omega * omega;
    }
    /* scaled elimination without row interchanges */
    const double *s = P->scale + cfg * nd;
    double big = 0.0;
    for (int i = 0; i < nd; i++)
        for (int j = 0; j < nd; j++) {
            double v = K[i * nd + j] * s[i] * s[j];
            K[i * nd + j] = v;
            if (fabs(v) > big) big = v < 0 ? -v : v;
        }
    double floor_ = 1e-14 * big, det = 1.0;
    int neg = 0;
    for (int k = 0; k < nd; k++) {
        double d = K[k * nd + k];
        if (d == 0.0) d = floor_;
        if (d < 0) neg++;
        det *= d;
        for (int i = k + 1; i < nd; i++) {
            double l = K[i * nd + k] / d;
            if (l == 0.0) continue;
            for (int j = k + 1; j < nd; j++) K[i * nd + j] -= l * K[k * nd + j];
        }
    }
    *J_out = J0 + neg - P->n_h;
    *J0_out = J0;
    *det_out = det;
}

static double estimate(const Problem *P, long long cfg, double x) {
    double L = P->length[cfg], H = P->H[cfg], m = P->m[cfg], EI = P->EI[cfg];
    double k = x * M_PI / L;
    return k * sqrt(H / m) * sqrt(1.0 + k * k * EI / H);
}

typedef struct { double x, f; int J, J0, has_f; } Point;

/* The first evaluation of the last item solved, at the estimate of its mode + ½: the next item's, of the
 * same configuration and the next mode, evaluates there again (at its mode − ½), and evaluate depends on
 * its configuration and ω alone, so that item takes it from here, the same numbers without the work. */
typedef struct { long long cfg; Point at; int valid; } Memo;

static int solve_one(const Problem *P, long long cfg, long long mode, double *result, Memo *memo) {
    Point lo = {0.0, NAN, 0, 0, 0}, hi, t;
    hi.x = estimate(P, cfg, mode + 0.5);
    evaluate(P, cfg, hi.x, &hi.J, &hi.J0, &hi.f); hi.has_f = 1;
    Point first = hi;
    int steps = 0;
    while (hi.J < mode) {
        lo = hi;
        hi.x *= 2.0;
        evaluate(P, cfg, hi.x, &hi.J, &hi.J0, &hi.f);
        if (++steps > 60) return -1;
    }
    if (mode > 1) {
        t.x = estimate(P, cfg, mode - 0.5);
        if (t.x > lo.x && t.x < hi.x) {
            if (memo->valid && memo->cfg == cfg && memo->at.x == t.x) t = memo->at;
            else { evaluate(P, cfg, t.x, &t.J, &t.J0, &t.f); t.has_f = 1; }
            if (t.J < mode) lo = t; else hi = t;
        }
    }
    memo->cfg = cfg; memo->at = first; memo->valid = 1;
    int side = 0, stalled = 0;
    double width_ref = hi.x - lo.x;
    for (int it = 0; it < MAX_ITER; it++) {
        double width = hi.x - lo.x;
        if (width <= RTOL * hi.x) {
            *result = 0.5 * (lo.x + hi.x);
            return 0;
        }
        int smooth = (hi.J - lo.J == 1) && (hi.J0 == lo.J0) && lo.has_f && hi.has_f && isfinite(lo.f) && isfinite(hi.f);
        double x = 0.5 * (lo.x + hi.x);
        if (smooth && stalled < 4) {
            double secant = hi.x - hi.f * width / (hi.f - lo.f);
            if (secant >= lo.x && secant <= hi.x) {
                double step = 0.25 * RTOL * hi.x;
                if (secant < lo.x + step) secant = lo.x + step;
                if (secant > hi.x - step) secant = hi.x - step;
                x = secant;
            }
        }
        t.x = x;
        evaluate(P, cfg, x, &t.J, &t.J0, &t.f); t.has_f = 1;
        if (t.f == 0.0) {
            *result = x;
            return 0;
        }
        if (t.J >= mode) {
            if (side == 1) { double mm = 1.0 - t.f / hi.f; lo.f *= mm > 0 ? mm : 0.5; }
            hi = t; side = 1;
        } else {
            if (side == -1) { double mm = 1.0 - t.f / lo.f; hi.f *= mm > 0 ? mm : 0.5; }
            lo = t; side = -1;
        }
        double new_width = hi.x - lo.x;
        if (new_width <= 0.5 * width_ref) { width_ref = new_width; stalled = 0; }
        else stalled++;
    }
    return -2;
}

/* Whether configurations a and b have identical inputs (bit for bit), so identical roots. */
static int same_config(const Problem *P, long long a, long long b) {
    int nd = P->n_dof, ns = P->n_seg, na = P->n_att;
    if (a == b) return 1;
#define SAME(arr, n) (memcmp((arr) + a * (n), (arr) + b * (n), sizeof(double) * (size_t)(n)) == 0)
    return SAME(P->length, 1) && SAME(P->m, 1) && SAME(P->EI, 1) && SAME(P->H, 1) && SAME(P->w, 1)
        && SAME(P->seg_len, ns) && SAME(P->masses, na) && SAME(P->scale, nd) && SAME(P->kconst, nd * nd);
#undef SAME
}

static uint64_t fnv1a(uint64_t h, const void *data, size_t n) {
    const unsigned char *p = data;
    for (size_t i = 0; i < n; i++) { h ^= p[i]; h *= 1099511628211ULL; }
    return h;
}

static uint64_t config_hash(const Problem *P, long long c) {
    int nd = P->n_dof, ns = P->n_seg, na = P->n_att;
    uint64_t h = 14695981039346656037ULL;
#define MIX(arr, n) h = fnv1a(h, (arr) + c * (n), sizeof(double) * (size_t)(n))
    MIX(P->length, 1); MIX(P->m, 1); MIX(P->EI, 1); MIX(P->H, 1); MIX(P->w, 1);
    MIX(P->seg_len, ns); MIX(P->masses, na); MIX(P->scale, nd); MIX(P->kconst, nd * nd);
#undef MIX
    return h;
}

/* source[i] = an earlier item with the same mode and identical inputs, or -1: such an item
 * (the rows of a finite-difference Jacobian that do not move a test's parameters are copies
 * of its base row) takes that item's root instead of being solved again. Returns 0, or -1
 * when out of memory (then nothing is shared). */
static int find_repeats(const Problem *P, const long long *config, const long long *mode, Py_ssize_t n,
                        long long *source) {
    size_t cap = 16;
    while (cap < 2 * (size_t)n) cap <<= 1;
    long long *table = malloc(cap * sizeof(long long));
    uint64_t *hashes = malloc((size_t)(n > 0 ? n : 1) * sizeof(uint64_t));
    if (!table || !hashes) { free(table); free(hashes); return -1; }
    for (size_t k = 0; k < cap; k++) table[k] = -1;
    long long last_cfg = -1;
    uint64_t last_hash = 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        if (config[i] != last_cfg) { last_cfg = config[i]; last_hash = config_hash(P, last_cfg); }
        uint64_t h = last_hash ^ ((uint64_t)mode[i] * 0x9E3779B97F4A7C15ULL);
        hashes[i] = h;
        source[i] = -1;
        size_t slot = (size_t)(h ^ (h >> 29)) & (cap - 1);
        for (;;) {
            long long j = table[slot];
            if (j < 0) { table[slot] = i; break; }
            if (hashes[j] == h && mode[j] == mode[i] && same_config(P, config[j], config[i])) { source[i] = j; break; }
            slot = (slot + 1) & (cap - 1);
        }
    }
    free(table);
    free(hashes);
    return 0;
}

/* solve(topology ints, arrays..., config, mode) -> (bytes of float64 ω per item, number failed) */
static PyObject *py_solve(PyObject *self, PyObject *args) {
    int n_att, n_dof, n_h, string, tension_model;
    PyObject *objs[PROBLEM_ARRAYS + 2];
    if (!PyArg_ParseTuple(args, "iiiiiOOOOOOOOOOOOOO", &n_att, &n_dof, &n_h, &string, &tension_model,
                          &objs[0], &objs[1], &objs[2], &objs[3], &objs[4], &objs[5], &objs[6], &objs[7],
                          &objs[8], &objs[9], &objs[10], &objs[11], &objs[12], &objs[13]))
        return NULL;
    static const char *const names[PROBLEM_ARRAYS + 2] = {PROBLEM_ARRAY_NAMES, "config", "mode"};
    Py_buffer views[PROBLEM_ARRAYS + 2];
    Problem P;
    PyObject *result = NULL;
    int got = open_buffers(objs, names, PROBLEM_ARRAYS + 2, views);
    if (got < PROBLEM_ARRAYS + 2 || problem_of(&P, n_att, n_dof, n_h, string, tension_model, views, NULL) != 0)
        goto done;
    const long long *config = views[12].buf, *mode = views[13].buf;
    Py_ssize_t n_items = views[12].len / (Py_ssize_t)sizeof(long long);
    PyObject *out = PyBytes_FromStringAndSize(NULL, n_items * (Py_ssize_t)sizeof(double));
    if (!out) goto done;
    double *omega = (double *)PyBytes_AS_STRING(out);
    Py_ssize_t failed = 0;
    long long *source = malloc((size_t)(n_items > 0 ? n_items : 1) * sizeof(long long));
    Memo memo = {0, {0.0, NAN, 0, 0, 0}, 0};
    Py_BEGIN_ALLOW_THREADS
    int shared = source && find_repeats(&P, config, mode, n_items, source) == 0;
    for (Py_ssize_t i = 0; i < n_items; i++) {
        if (shared && source[i] >= 0) {  /* an earlier item, solved already (source -2 if it failed) */
            omega[i] = omega[source[i]];
            failed += source[source[i]] == -2;
        } else if (solve_one(&P, config[i], mode[i], &omega[i], &memo) != 0) {
            omega[i] = NAN;
            failed++;
            if (shared) source[i] = -2;
        }
    }
    Py_END_ALLOW_THREADS
    free(source);
    result = Py_BuildValue("Nn", out, failed);
done:
    close_buffers(views, got);
    return result;
}

static PyMethodDef methods[] = {
    {"solve", py_solve, METH_VARARGS, "Natural frequencies (rad/s) of (configuration, mode) items."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_dsm_kernel", NULL, -1, methods};

PyMODINIT_FUNC PyInit__dsm_kernel(void) { return PyModule_Create(&module); }
