/*
 * Segment dynamic stiffness and its assembly, written once for both compiled kernels over the scalar
 * type: real ω in _dsm_kernel.c, complex ω = −i s in _damped_kernel.c. A kernel defines SEGMENT_COMPLEX
 * (after including complex.h) or not, then includes this file once; SCALAR is then its scalar type.
 * The shared problem layout and the real clamped–clamped count J0 are in _problem.h.
 *
 * The numerics are those of elements.py and assembly.py: each segment in the stable exponential form
 * (symmetric and antisymmetric parts about its middle), the series of x cos x − sin x, x − tanh x and
 * x − tan x below |x| = 0.1 where the closed forms cancel, and with a tension model the segments'
 * coupling to the tension increments (the sag term). Kept expression for expression as the two
 * kernels had them, so each gives the same numbers bit for bit.
 */
#ifndef STCS_IDENT_SEGMENT_H
#define STCS_IDENT_SEGMENT_H

#include "_problem.h"

#ifdef SEGMENT_COMPLEX
#define SCALAR double complex
#define ABS cabs
#define SQRT csqrt
#define TANH ctanh
#define TAN ctan
/* sin z and cos z from one complex exponential (|Im z| stays far below overflow on the contours). */
static void sin_cos(SCALAR z, SCALAR *s, SCALAR *c) {
    SCALAR e = cexp(I * z), r = 1.0 / e;
    *s = (e - r) / (2.0 * I);
    *c = 0.5 * (e + r);
}
#else
#define SCALAR double
#define ABS fabs
#define SQRT sqrt
#define TANH tanh
#define TAN tan
static void sin_cos(double x, double *s, double *c) {
    *s = sin(x);
    *c = cos(x);
}
#endif

/* x cos x − sin x, given sin x and cos x, without cancellation near 0. */
static SCALAR x_cos_minus_sin(SCALAR x, SCALAR sn, SCALAR cs) {
    SCALAR x2 = x * x;
    if (ABS(x) < 0.1) return x * x2 * (-1.0 / 3 + x2 * (1.0 / 30 + x2 * (-1.0 / 840 + x2 / 45360)));
    return x * cs - sn;
}

/* x − tanh x, given tanh x, without cancellation near 0. */
static SCALAR x_minus_tanh(SCALAR x, SCALAR th) {
    SCALAR x2 = x * x;
    if (ABS(x) < 0.1) return x * x2 * (1.0 / 3 + x2 * (-2.0 / 15 + x2 * (17.0 / 315 - x2 * 62.0 / 2835)));
    return x - th;
}

/* x − tan x without cancellation near 0. */
static SCALAR x_minus_tan(SCALAR x) {
    SCALAR x2 = x * x;
    if (ABS(x) < 0.1) return -x * x2 * (1.0 / 3 + x2 * (2.0 / 15 + x2 * (17.0 / 315 + x2 * 62.0 / 2835)));
    return x - TAN(x);
}

/* Beam segment of length L at ω: element matrix Ke (row-major 4×4 on v, θ, v, θ), the translation
 * force of a unit tension increment and its residual R. Returns the segment's J0 at a real ω (counted
 * here from the same p and q; 0 for a complex ω, whose count is clamped_count on the real axis). */
static int beam_segment(double L, double EI, double H, double m, SCALAR omega, SCALAR Ke[16], SCALAR force[4],
                         SCALAR *R) {
    double half = 0.5 * L;
    double a_ = H / (2.0 * EI);
    SCALAR b_ = m * omega * omega / EI;
    SCALAR root = SQRT(a_ * a_ + b_);
    SCALAR p2 = a_ + root, q2 = b_ / p2;
    SCALAR p = SQRT(p2), q = SQRT(q2);
    SCALAR pl = p * half, ql = q * half;
    SCALAR T = TANH(pl), s, c;
    sin_cos(ql, &s, &c);
    SCALAR ppqq = p2 + q2, pq = p * q;
    /* n_anti = T q c − s p without the cancellation of its leading terms on a short segment */
    SCALAR xcs = x_cos_minus_sin(ql, s, c), xt = x_minus_tanh(pl, T);
    SCALAR n_sym = q * s + p * T * c, n_anti = p * xcs - q * c * xt;
    SCALAR k1 = EI / n_sym, k2 = EI / n_anti;
    SCALAR a = -k1 * pq * T * s * ppqq, b = -k1 * pq * n_anti, d = k1 * c * ppqq;
    SCALAR e = -k2 * pq * c * ppqq, f = k2 * pq * n_sym, h = -k2 * T * s * ppqq;
    Ke[0] = Ke[10] = 0.5 * (a + e);
    Ke[5] = Ke[15] = 0.5 * (d + h);
    Ke[2] = Ke[8] = 0.5 * (a - e);
    Ke[7] = Ke[13] = 0.5 * (h - d);
    Ke[1] = Ke[4] = -0.5 * (b + f);
    Ke[11] = Ke[14] = 0.5 * (b + f);
    Ke[3] = Ke[12] = 0.5 * (b - f);
    Ke[6] = Ke[9] = 0.5 * (f - b);
    force[0] = a; force[1] = -b; force[2] = a; force[3] = b;
    *R = 2.0 * EI * pq * (p2 * T * xcs + q2 * s * xt) / n_sym;
#ifdef SEGMENT_COMPLEX
    return 0;
#else
    return beam_clamped_count(p, q, p2, q2, 2.0 * pl, 2.0 * ql);
#endif
}

/* String segment (EI = 0) of length L at ω: Ke (2×2 on v, v), force, R and J0 as beam_segment. */
static int string_segment(double L, double H, double m, SCALAR omega, SCALAR Ke[4], SCALAR force[2], SCALAR *R) {
    double half = 0.5 * L;
    SCALAR q = omega * sqrt(m / H);
    SCALAR ql2 = 2.0 * q * half;
    SCALAR sn, cs;
    sin_cos(ql2, &sn, &cs);
    SCALAR diag = H * q * cs / sn, off = -H * q / sn;
    Ke[0] = Ke[3] = diag;
    Ke[1] = Ke[2] = off;
    force[0] = force[1] = diag + off;
    *R = 2.0 * H * q * x_minus_tan(q * half);
#ifdef SEGMENT_COMPLEX
    return 0;
#else
    return string_clamped_count(ql2);
#endif
}

/* K (n_dof × n_dof, row-major) of configuration cfg at ω without the attachments: the constant part
 * (boundary springs), every segment, and with a tension model the segments' coupling to the tension
 * increments. Returns J0 at a real ω (0 for a complex one). */
static int assemble(const Problem *P, long long cfg, SCALAR omega, SCALAR *K) {
    int nd = P->n_dof, ns = P->n_seg;
    const double *kconst = P->kconst + cfg * nd * nd;
    for (int i = 0; i < nd * nd; i++) K[i] = kconst[i];
    double m = P->m[cfg], H = P->H[cfg], EI = P->EI[cfg];
    SCALAR gamma = P->w[cfg] / (H * m * omega * omega);
    int J0 = 0;
    for (int j = 0; j < ns; j++) {
        SCALAR Ke[16], force[4], R;
        long long dofs[4];
        int ne;
        double L = P->seg_len[cfg * ns + j];
        if (P->string) {
            ne = 2;
            J0 += string_segment(L, H, m, omega, Ke, force, &R);
            dofs[0] = P->v_dof[j]; dofs[1] = P->v_dof[j + 1];
        } else {
            ne = 4;
            J0 += beam_segment(L, EI, H, m, omega, Ke, force, &R);
            dofs[0] = P->v_dof[j]; dofs[1] = P->t_dof[j];
            dofs[2] = P->v_dof[j + 1]; dofs[3] = P->t_dof[j + 1];
        }
        for (int r = 0; r < ne; r++) {
            if (dofs[r] < 0) continue;
            for (int c = 0; c < ne; c++)
                if (dofs[c] >= 0) K[dofs[r] * nd + dofs[c]] += Ke[r * ne + c];
        }
        if (P->tension_model != 0) {
            long long hj = P->h_dof[P->tension_model == 1 ? 0 : j];
            for (int r = 0; r < ne; r++) {
                if (dofs[r] < 0) continue;
                SCALAR v = -gamma * force[r];
                K[dofs[r] * nd + hj] += v;
                K[hj * nd + dofs[r]] += v;
            }
            K[hj * nd + hj] += gamma * gamma * R;
        }
    }
    return J0;
}

#undef ABS
#undef SQRT
#undef TANH
#undef TAN

#endif
