/*
 * Shared by the compiled kernels _dsm_kernel.c (real ω) and _damped_kernel.c (complex s = iω): the
 * problem as the Python callers pass it (roots._solve_compiled, damped._solve_compiled), opening its
 * buffers, and the clamped–clamped count J0 of the segments (the poles of det K on the real axis).
 * Included after Python.h; the segment matrices, written once over the scalar type, are in _segment.h.
 */
#ifndef STCS_IDENT_PROBLEM_H
#define STCS_IDENT_PROBLEM_H

#include <math.h>

#define MAX_DOF 64

typedef struct {
    int n_att, n_seg, n_dof, n_h, string, tension_model; /* 0 none, 1 uniform, 2 per-segment */
    const long long *v_dof, *t_dof, *h_dof;
    const double *length, *m, *EI, *H, *w, *seg_len, *masses, *kconst, *scale;
    const double *dash; /* dashpots (configurations × n_att), complex kernel only; NULL in the real one */
} Problem;

/* The arrays both kernels take first, in this order (v_dof ... scale of Problem). */
#define PROBLEM_ARRAYS 12
#define PROBLEM_ARRAY_NAMES "v_dof", "t_dof", "h_dof", "length", "m", "EI", "H", "w", "seg_len", "masses", \
                            "kconst", "scale"

/* Opens objs[0 .. n) as C-contiguous buffers into views; returns how many were opened (n on success,
 * else a TypeError naming the argument is set and the caller releases those opened). */
static int open_buffers(PyObject *const *objs, const char *const *names, int n, Py_buffer *views) {
    for (int k = 0; k < n; k++)
        if (PyObject_GetBuffer(objs[k], &views[k], PyBUF_C_CONTIGUOUS) < 0) {
            PyErr_Format(PyExc_TypeError, "%s: a contiguous buffer is required", names[k]);
            return k;
        }
    return n;
}

static void close_buffers(Py_buffer *views, int n) {
    for (int k = 0; k < n; k++) PyBuffer_Release(&views[k]);
}

/* The topology and the first PROBLEM_ARRAYS buffers as *P; 0, or −1 with a ValueError set when the problem
 * has more degrees of freedom than the kernels' fixed-size matrices hold. */
static int problem_of(Problem *P, int n_att, int n_dof, int n_h, int string, int tension_model,
                      const Py_buffer *views, const double *dash) {
    if (n_dof > MAX_DOF) {
        PyErr_SetString(PyExc_ValueError, "too many degrees of freedom for the compiled kernel");
        return -1;
    }
    Problem p = {n_att, n_att + 1, n_dof, n_h, string, tension_model,
                 views[0].buf, views[1].buf, views[2].buf,
                 views[3].buf, views[4].buf, views[5].buf, views[6].buf, views[7].buf, views[8].buf,
                 views[9].buf, views[10].buf, views[11].buf, dash};
    *P = p;
    return 0;
}

/* Clamped–clamped frequencies below a real ω of a beam segment, from its p, q, p², q² at ω and
 * pL = p L, qL = q L. */
static int beam_clamped_count(double p, double q, double p2, double q2, double pL, double qL) {
    double ex = exp(-pL);
    double delta = 2 * p * q * (ex * 2.0 / (1.0 + ex * ex) - cos(qL)) + (p2 - q2) * tanh(pL) * sin(qL);
    double i = floor(qL / M_PI);
    if (i < 1) return 0;
    double parity = fmod(i, 2.0) == 0.0 ? 1.0 : -1.0;
    return (int)(i - 1) + (((delta > 0) - (delta < 0)) == parity);
}

/* The same for a string segment, from qL = ω √(m/H) L. */
static int string_clamped_count(double qL) {
    double n = ceil(qL / M_PI) - 1;
    return n > 0 ? (int)n : 0;
}

/* J0 of configuration cfg at a real ω: the number of clamped–clamped segment frequencies below it (the
 * complex kernel's count on the contour; the real kernel counts while it assembles). */
static inline int clamped_count(const Problem *P, long long cfg, double omega) {
    int J0 = 0;
    double m = P->m[cfg], H = P->H[cfg], EI = P->EI[cfg];
    for (int j = 0; j < P->n_seg; j++) {
        double L = P->seg_len[cfg * P->n_seg + j];
        if (P->string) {
            J0 += string_clamped_count(omega * sqrt(m / H) * L);
            continue;
        }
        double a_ = H / (2.0 * EI), b_ = m * omega * omega / EI;
        double p2 = a_ + sqrt(a_ * a_ + b_), q2 = b_ / p2, p = sqrt(p2), q = sqrt(q2);
        J0 += beam_clamped_count(p, q, p2, q2, p * L, q * L);
    }
    return J0;
}

#endif
