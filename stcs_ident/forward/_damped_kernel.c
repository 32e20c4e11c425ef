/*
 * Compiled kernel of the complex-mode solver (optional): the same numerics as damped.py, one
 * damped configuration at a time. K(s) is the undamped dynamic stiffness (segments in the stable
 * form of elements.py, the sag term of assembly.py) at ω = −i s, plus t c s on each damper's
 * displacement; its determinant's zeros (scaled, LU with partial pivoting) are followed from the
 * undamped roots to t = 1 (in one step from a Möbius model of the path, else by geometric steps
 * in t, shortened on failure, the secant method as corrector; a path that falls onto another's
 * root solved again from its pinned end with the roots found divided out), and the count is certified by the argument
 * principle on a quadrilateral (damping ratio below 0.5), the phase followed by recursive bisection of the edges (no step of more than π/4). It exists because
 * numpy's per-call overhead dominates these small problems; damped.py stays the reference and the
 * tests compare the two. The segments, their assembly and J0 are written once with the real kernel
 * (_segment.h over the scalar type, _problem.h).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define SECANT_RTOL 1e-10
#define SECANT_ITER 40
#define START 0.01
#define GROWTH 4.0
#define MIN_RATIO (1 + 1e-6)
#define SMOOTH 0.5
#define DUPLICATE 1e-8
#define NEAR 16
#define MAX_MODES 512
#define MAX_DAMPING 0.5
#define DEFLATE 8
#define LINE_POINTS 64
#define SEARCH_DEPTH 30
#define JUMP 0.25
#define MAX_ARG_STEP (M_PI / 4)
#define MAX_CONTOUR_POINTS 200000

#define SEGMENT_COMPLEX
#include "_segment.h"

typedef double complex cplx;

/* det of the scaled K(s) of configuration cfg with the dashpots times t. */
static cplx cdet(const Problem *P, long long cfg, cplx s, double t) {
    int nd = P->n_dof;
    cplx K[MAX_DOF * MAX_DOF];
    cplx omega = -I * s;
    assemble(P, cfg, omega, K);
    for (int k = 0; k < P->n_att; k++) {
        long long v = P->v_dof[k + 1];
        K[v * nd + v] += -P->masses[cfg * P->n_att + k] * omega * omega + t * P->dash[cfg * P->n_att + k] * s;
    }
    const double *sc = P->scale + cfg * nd;
    for (int i = 0; i < nd; i++)
        for (int j = 0; j < nd; j++) K[i * nd + j] *= sc[i] * sc[j];
    cplx det = 1.0;
    for (int k = 0; k < nd; k++) {  /* LU with partial pivoting */
        int piv = k;
        double best = cabs(K[k * nd + k]);
        for (int i = k + 1; i < nd; i++)
            if (cabs(K[i * nd + k]) > best) { best = cabs(K[i * nd + k]); piv = i; }
        if (best == 0.0) return 0.0;
        if (piv != k) {
            for (int j = k; j < nd; j++) { cplx tmp = K[k * nd + j]; K[k * nd + j] = K[piv * nd + j]; K[piv * nd + j] = tmp; }
            det = -det;
        }
        cplx d = K[k * nd + k];
        det *= d;
        for (int i = k + 1; i < nd; i++) {
            cplx l = K[i * nd + k] / d;
            if (l == 0.0) continue;
            for (int j = k + 1; j < nd; j++) K[i * nd + j] -= l * K[k * nd + j];
        }
    }
    return det;
}

/* det K(z) divided by (z − r) for the n roots r of defl (none when n = 0). */
static cplx fdefl(const Problem *P, long long cfg, cplx z, double t, const cplx *defl, int n) {
    cplx f = cdet(P, cfg, z, t);
    for (int j = 0; j < n; j++) f /= z - defl[j];
    return f;
}

/* A root by the secant method from a (value fa) and b, deflated by defl; 0 and *root, or −1. */
static int secant_d(const Problem *P, long long cfg, double t, cplx a, cplx fa, cplx b, const cplx *defl, int n,
                    cplx *root) {
    for (int it = 0; it < SECANT_ITER; it++) {
        cplx fb = fdefl(P, cfg, b, t, defl, n);
        if (!isfinite(creal(fb)) || !isfinite(cimag(fb))) return -1;
        if (fb == 0.0) { *root = b; return 0; }
        if (fb == fa) return -1;
        cplx step = fb * (b - a) / (fb - fa);
        a = b; fa = fb; b = b - step;
        if (cabs(step) <= SECANT_RTOL * cabs(b)) { *root = b; return 0; }
    }
    return -1;
}

static int secant(const Problem *P, long long cfg, double t, cplx a, cplx fa, cplx b, cplx *root) {
    return secant_d(P, cfg, t, a, fa, b, NULL, 0, root);
}

/* The root from s0 at t = 0 to t = 1 by geometric steps in t; 0, or −1. */
static int follow_in_steps(const Problem *P, long long cfg, cplx s0, cplx first, double reach, cplx *out) {
    double t = START * reach / cabs(first);
    if (t > 1.0) t = 1.0;
    cplx s, s1, prev_s = 0.0;
    double prev_t = 0.0, ratio = GROWTH;
    int have_prev = 0;
    if (secant(P, cfg, t, s0, cdet(P, cfg, s0, t), s0 + first * t, &s) != 0) return -1;
    while (t < 1.0) {
        double t1 = t * ratio < 1.0 ? t * ratio : 1.0;
        cplx guess = have_prev ? s + (s - prev_s) * ((t1 - t) / (t - prev_t)) : s + first * (t1 - t);
        if (secant(P, cfg, t1, s, cdet(P, cfg, s, t1), guess, &s1) != 0 || cabs(s1 - s) > reach
            || cabs(s1 - guess) > SMOOTH * cabs(guess - s)) {
            ratio = sqrt(ratio);
            if (ratio < MIN_RATIO) return -1;
            continue;
        }
        prev_t = t; prev_s = s; have_prev = 1;
        s = s1; t = t1;
        ratio = ratio * ratio < GROWTH ? ratio * ratio : GROWTH;
    }
    *out = s;
    return 0;
}

/* Each undamped root omega[k] followed to t = 1; the number of modes that could not be followed (NaN). */
static int follow(const Problem *P, long long cfg, const double *omega, const double *pinned, int n, cplx *out) {
    int lost = 0;
    for (int k = 0; k < n; k++) {
        double below = omega[k] - (k > 0 ? omega[k - 1] : 0.0);
        double above = k + 1 < n ? omega[k + 1] - omega[k] : (n > 1 ? omega[k] - omega[k - 1] : omega[k]);
        double reach = JUMP * (below < above ? below : above);
        cplx s0 = I * omega[k], s;
        double h = 1e-7 * omega[k];
        cplx f1 = cdet(P, cfg, s0, 1.0);
        cplx first = -f1 * 2 * h / (cdet(P, cfg, s0 + h, 0.0) - cdet(P, cfg, s0 - h, 0.0));
        cplx guess = s0 + 1.0 / (1.0 / first + 1.0 / (I * (pinned[k] - omega[k])));
        double tight = SMOOTH * cabs(guess - s0) < reach ? SMOOTH * cabs(guess - s0) : reach;
        cplx near_guess = guess + 1e-3 * (guess - s0);  /* the secant from the prediction: local */
        if (secant(P, cfg, 1.0, guess, cdet(P, cfg, guess, 1.0), near_guess, &s) != 0 || cabs(s - guess) > tight)
            if (follow_in_steps(P, cfg, s0, first, reach, &s) != 0) {
                out[k] = NAN;
                lost++;
                continue;
            }
        int fell = 0;
        for (int j = 0; j < k; j++) fell |= cabs(out[j] - s) <= DUPLICATE * cabs(s);  /* NaN: false */
        if (fell) {  /* another path's root (a near crossing): the nearby roots divided out, from the start */
            cplx near[MAX_MODES];
            int n_near = 0;
            for (int j = 0; j < k && n_near < MAX_MODES; j++)
                if (cabs(out[j] - s0) < NEAR * reach) near[n_near++] = out[j];  /* NaN: left out */
            cplx end = I * pinned[k];
            double left = 0.3 * cabs(end - s0);  /* off the axis: poles sit on it */
            cplx starts[2][2] = {{end - left, 0.5 * (s0 + end) - left}, {s0, guess}};
            int ok = 0;
            for (int a = 0; a < 2 && !ok; a++) {
                if (secant_d(P, cfg, 1.0, starts[a][0], fdefl(P, cfg, starts[a][0], 1.0, near, n_near), starts[a][1],
                             near, n_near, &s) != 0 || !(cimag(s) > 0))
                    continue;
                ok = 1;
                for (int j = 0; j < k; j++) ok &= cabs(out[j] - s) > DUPLICATE * cabs(s);
            }
            if (!ok) {
                out[k] = NAN;
                lost++;
                continue;
            }
        }
        out[k] = s;
    }
    return lost;
}

typedef struct { const Problem *P; long long cfg; long points; } Contour;

/* Phase change of det K from a (value fa) to b (value fb), bisecting until each step is small. */
static int phase(Contour *C, cplx a, cplx fa, cplx b, cplx fb, double *total) {
    cplx ratio = fb / fa;
    double step = carg(ratio), mag = fabs(log(cabs(ratio)));
    if (fabs(step) <= MAX_ARG_STEP && mag < 1.0) { *total += step; return 0; }
    if (++C->points > MAX_CONTOUR_POINTS) return -1;
    cplx mid = 0.5 * (a + b);
    cplx fm = cdet(C->P, C->cfg, mid, 1.0);
    if (phase(C, a, fa, mid, fm, total) != 0) return -1;
    return phase(C, mid, fm, b, fb, total);
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Where on the edge a → b (0 <= u < 1) the phase is first sampled (as damped.edge_parameters): spacing
 * apart near the imaginary axis, a quarter of the distance to it farther out, and, on an edge crossing
 * the axis, ever closer to it. Returns the count, or −1. */
static int edge_parameters(cplx a, cplx b, double spacing, double **u_out) {
    double length = cabs(b - a);
    int cap = 64, m = 0;
    double *u = malloc(sizeof(double) * (size_t)(cap + 80));
    if (!u) return -1;
    for (double at = 0.0; at < 1.0;) {
        if (m == cap) {
            cap *= 2;
            double *v = realloc(u, sizeof(double) * (size_t)(cap + 80));
            if (!v) { free(u); return -1; }
            u = v;
        }
        u[m++] = at;
        double x = fabs(creal(a + (b - a) * at)), step = 0.25 * x > spacing ? 0.25 * x : spacing;
        at += step / length;
    }
    double ar = creal(a), br = creal(b);
    if (cimag(a) == cimag(b) && fmin(ar, br) < 0 && 0 < fmax(ar, br)) {
        for (int k = 1; k <= 20; k++)
            for (int sgn = -1; sgn <= 1; sgn += 2) {
                double v = (sgn * spacing * ldexp(1.0, -2 * k) - ar) / (br - ar);
                if (v >= 0 && v < 1) u[m++] = v;
            }
        qsort(u, (size_t)m, sizeof(double), cmp_double);
        int w = 1;
        for (int k = 1; k < m; k++) if (u[k] != u[w - 1]) u[w++] = u[k];
        m = w;
    }
    *u_out = u;
    return m;
}

/* Turns of det K around 0 along the quadrilateral Im s in [lo, hi], −slope Im s < Re s < right
 * (counter-clockwise), sampled every spacing; 0 or −1. */
static int winding(const Problem *P, long long cfg, double lo, double hi, double slope, double right, double spacing,
                   int *turns) {
    cplx corners[5] = {right + I * lo, right + I * hi, (-slope + I) * hi, (-slope + I) * lo, right + I * lo};
    Contour C = {P, cfg, 0};
    double total = 0.0;
    cplx z0 = corners[0], f0 = cdet(P, cfg, z0, 1.0);
    cplx z = z0, fz = f0;
    for (int e = 0; e < 4; e++) {
        double *u;
        int m = edge_parameters(corners[e], corners[e + 1], spacing, &u);
        if (m < 0) return -1;
        for (int k = 1; k <= m; k++) {
            int last = k == m;
            cplx zn = last ? corners[e + 1] : corners[e] + (corners[e + 1] - corners[e]) * u[k];
            cplx fn = (last && e == 3) ? f0 : cdet(P, cfg, zn, 1.0);
            if (phase(&C, z, fz, zn, fn, &total) != 0) { free(u); return -1; }
            z = zn; fz = fn;
        }
        free(u);
    }
    *turns = (int)lround(total / (2 * M_PI));
    return 0;
}

typedef struct { double lo, right, slope, spacing; } Region;

static int in_region(cplx z, const Region *R, double lo, double hi) {
    return cimag(z) > lo && cimag(z) < hi && creal(z) < R->right && creal(z) > -R->slope * cimag(z);
}

/* Eigenvalues in the band (lo, hi) of the region: winding number plus poles (J0); 0 or −1. */
static int count_zeros(const Problem *P, long long cfg, const Region *R, double lo, double hi, int *zeros) {
    int turns;
    if (winding(P, cfg, lo, hi, R->slope, R->right, R->spacing, &turns) != 0) return -1;
    *zeros = turns + clamped_count(P, cfg, hi) - clamped_count(P, cfg, lo);
    return 0;
}

static int is_known(cplx z, const cplx *known, int nk) {
    for (int j = 0; j < nk; j++) if (cabs(known[j] - z) <= DUPLICATE * cabs(z)) return 1;
    return 0;
}

/* The one eigenvalue of the band that known lacks (as damped._locate); 0 and *root, or −1. */
static int locate(const Problem *P, long long cfg, const Region *R, double lo, double hi, const cplx *known, int nk,
                  cplx *root) {
    double mid = 0.5 * (lo + hi);
    cplx near[DEFLATE];
    int nn = 0;
    int used[MAX_MODES] = {0};
    for (; nn < DEFLATE && nn < nk; nn++) {  /* the nearest known roots, divided out */
        int best = -1;
        for (int j = 0; j < nk && j < MAX_MODES; j++)
            if (!used[j] && (best < 0 || cabs(known[j] - I * mid) < cabs(known[best] - I * mid))) best = j;
        if (best < 0) break;
        used[best] = 1;
        near[nn] = known[best];
    }
    static const double zetas[5] = {1e-4, 1e-3, 0.01, 0.1, 0.3};
    cplx best = I * mid;  /* the smallest |det K| across the band's middle, away from the known roots */
    double smallest = INFINITY;
    for (int j = 0; j < LINE_POINTS; j++) {
        cplx z = mid * (I - R->slope * (double)j / (LINE_POINTS - 1));
        int clear = 1;
        for (int i = 0; i < nn; i++) clear &= cabs(z - near[i]) >= 0.02 * mid;
        if (!clear) continue;
        double v = cabs(cdet(P, cfg, z, 1.0));
        if (v < smallest) { smallest = v; best = z; }
    }
    for (int k = 0; k < 6; k++) {
        cplx a = k < 5 ? -zetas[k] * mid + I * mid : best, b = a + 0.1 * I * (hi - lo);
        if (secant_d(P, cfg, 1.0, a, fdefl(P, cfg, a, 1.0, near, nn), b, near, nn, root) == 0
            && in_region(*root, R, lo, hi) && !is_known(*root, known, nk))
            return 0;
    }
    return -1;
}

/* A point near the middle of (lo, hi), 2 % of the band from any known root's Im (as damped._split). */
static double split(double lo, double hi, const cplx *known, int nk) {
    static const double u[9] = {0.5, 0.45, 0.55, 0.4, 0.6, 0.35, 0.65, 0.3, 0.7};
    for (int k = 0; k < 9; k++) {
        double mid = lo + u[k] * (hi - lo);
        int clear = 1;
        for (int j = 0; j < nk; j++) clear &= fabs(cimag(known[j]) - mid) >= 0.02 * (hi - lo);
        if (clear) return mid;
    }
    return lo + 0.5 * (hi - lo);
}

/* The eigenvalues of the band that known lacks, appended to known (as damped._search); 0 or −1. */
static int search(const Problem *P, long long cfg, const Region *R, double lo, double hi, cplx *known, int *nk,
                  int depth) {
    int zeros, have = 0;
    if (count_zeros(P, cfg, R, lo, hi, &zeros) != 0) return -1;
    for (int j = 0; j < *nk; j++) have += in_region(known[j], R, lo, hi);
    int missing = zeros - have;
    if (missing <= 0) return 0;
    if (*nk >= MAX_MODES) return -1;
    if (missing == 1 && locate(P, cfg, R, lo, hi, known, *nk, &known[*nk]) == 0) {
        (*nk)++;
        return 0;
    }
    if (depth >= SEARCH_DEPTH) return -1;
    double mid = split(lo, hi, known, *nk);
    if (search(P, cfg, R, lo, mid, known, nk, depth + 1) != 0) return -1;
    return search(P, cfg, R, mid, hi, known, nk, depth + 1);
}

static int cmp_imag(const void *a, const void *b) {
    double x = cimag(*(const cplx *)a), y = cimag(*(const cplx *)b);
    return (x > y) - (x < y);
}

/* The first n_modes + 1 eigenvalues by Im s, certified (as damped.complete); s holds the paths' ends
 * (NaN where lost) and gets the result. 0, or a status of solve_config. */
static int complete(const Problem *P, long long cfg, const double *omega, cplx *s, int n_modes) {
    Region R = {0.25 * omega[0], 0.5 * omega[0], MAX_DAMPING / sqrt(1 - MAX_DAMPING * MAX_DAMPING), 0.25 * omega[0]};
    cplx roots[MAX_MODES];
    int nr = 0;
    for (int k = 0; k <= n_modes; k++)
        if (isfinite(creal(s[k])) && isfinite(cimag(s[k])) && in_region(s[k], &R, R.lo, INFINITY)
            && !is_known(s[k], roots, nr) && nr < MAX_MODES)
            roots[nr++] = s[k];
    double hi = 0.0;
    for (int round = 0; round < 2 * n_modes + 8; round++) {
        qsort(roots, (size_t)nr, sizeof(cplx), cmp_imag);
        if (nr > n_modes) {
            hi = 0.5 * (cimag(roots[n_modes - 1]) + cimag(roots[n_modes]));
        } else {
            double top = nr ? cimag(roots[nr - 1]) : omega[0];
            if (hi > top) top = hi;
            hi = top + 0.618 * (top - R.lo) / (nr > 0 ? nr : 1);
        }
        int zeros, inside = 0;
        if (count_zeros(P, cfg, &R, R.lo, hi, &zeros) != 0) return 3;
        for (int j = 0; j < nr; j++) inside += cimag(roots[j]) < hi;
        if (zeros < inside) return 4;
        if (zeros == inside && nr > n_modes) {
            for (int k = 0; k <= n_modes; k++) s[k] = roots[k];
            return 0;
        }
        if (zeros > inside && search(P, cfg, &R, R.lo, hi, roots, &nr, 0) != 0) return 6;
    }
    return 6;
}

/* Status: 0 ok, 1 a path failed and certification is off, 3 the contour did not resolve, 4 the count is
 * below the roots found, 6 a lost mode was not found again. */
static int solve_config(const Problem *P, long long cfg, const double *omega, const double *pinned, int n_modes,
                        int certify, cplx *s) {
    int lost = follow(P, cfg, omega, pinned, n_modes + 1, s);
    if (!certify) return lost ? 1 : 0;
    return complete(P, cfg, omega, s, n_modes);
}

/* solve(topology ints, arrays..., configs, omega (n_cfg_all × (n_modes+1)), pinned (configs × (n_modes+1)),
 *       n_modes, certify)
 * -> (bytes of complex128 s, configs × (n_modes+1)), bytes of int32 status per config) */
static PyObject *py_solve(PyObject *self, PyObject *args) {
    int n_att, n_dof, n_h, string, tension_model, n_modes, certify;
    PyObject *objs[PROBLEM_ARRAYS + 4];
    if (!PyArg_ParseTuple(args, "iiiii" "OOOOOOOOOOOOOOOO" "ii", &n_att, &n_dof, &n_h, &string, &tension_model,
                          &objs[0], &objs[1], &objs[2], &objs[3], &objs[4], &objs[5], &objs[6], &objs[7],
                          &objs[8], &objs[9], &objs[10], &objs[11], &objs[12], &objs[13], &objs[14], &objs[15],
                          &n_modes, &certify))
        return NULL;
    static const char *const names[PROBLEM_ARRAYS + 4] = {PROBLEM_ARRAY_NAMES, "dash", "configs", "omega", "pinned"};
    Py_buffer views[PROBLEM_ARRAYS + 4];
    Problem P;
    PyObject *result = NULL;
    int got = open_buffers(objs, names, PROBLEM_ARRAYS + 4, views);
    if (got < PROBLEM_ARRAYS + 4
        || problem_of(&P, n_att, n_dof, n_h, string, tension_model, views, views[12].buf) != 0)
        goto done;
    const long long *configs = views[13].buf;
    const double *omega = views[14].buf, *pinned = views[15].buf;
    Py_ssize_t n_cfg = views[13].len / (Py_ssize_t)sizeof(long long);
    int n = n_modes + 1;
    PyObject *out = PyBytes_FromStringAndSize(NULL, n_cfg * n * (Py_ssize_t)sizeof(cplx));
    PyObject *status = PyBytes_FromStringAndSize(NULL, n_cfg * (Py_ssize_t)sizeof(int));
    if (!out || !status) { Py_XDECREF(out); Py_XDECREF(status); goto done; }
    cplx *s = (cplx *)PyBytes_AS_STRING(out);
    int *st = (int *)PyBytes_AS_STRING(status);
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < n_cfg; i++)
        st[i] = solve_config(&P, configs[i], omega + configs[i] * n, pinned + i * n, n_modes, certify, s + i * n);
    Py_END_ALLOW_THREADS
    result = Py_BuildValue("NN", out, status);
done:
    close_buffers(views, got);
    return result;
}

/* Warm start: each of the n roots of configuration cfg by the secant method from start[k] (a nearby
 * configuration's root). 0 when every root converged within JUMP of the distance from its start to the
 * nearest other start, Im s > 0, the roots distinct and in the starts' order by Im s; else 7 (the caller
 * solves the configuration from its undamped roots instead). */
static int refine_config(const Problem *P, long long cfg, const cplx *start, int n, cplx *s) {
    for (int k = 0; k < n; k++) {
        cplx s0 = start[k];
        if (!isfinite(creal(s0)) || !isfinite(cimag(s0)) || !(cimag(s0) > 0)) return 7;
        double gap = INFINITY;
        for (int j = 0; j < n; j++)
            if (j != k && cabs(start[j] - s0) < gap) gap = cabs(start[j] - s0);
        if (!(gap > 0)) return 7;
        cplx b = s0 * (1 + 1e-7), root;
        if (secant(P, cfg, 1.0, s0, cdet(P, cfg, s0, 1.0), b, &root) != 0) return 7;
        if (!(cabs(root - s0) <= JUMP * gap) || !(cimag(root) > 0)) return 7;
        for (int j = 0; j < k; j++) {
            if (cabs(s[j] - root) <= DUPLICATE * cabs(root)) return 7;
            if ((cimag(start[j]) < cimag(s0)) != (cimag(s[j]) < cimag(root))) return 7;
        }
        s[k] = root;
    }
    return 0;
}

/* refine(topology ints, arrays..., configs, starts (configs × n), n) -> (bytes of complex128 s, configs × n,
 *        bytes of int32 status per config: 0 or 7) */
static PyObject *py_refine(PyObject *self, PyObject *args) {
    int n_att, n_dof, n_h, string, tension_model, n;
    PyObject *objs[PROBLEM_ARRAYS + 3];
    if (!PyArg_ParseTuple(args, "iiiii" "OOOOOOOOOOOOOOO" "i", &n_att, &n_dof, &n_h, &string, &tension_model,
                          &objs[0], &objs[1], &objs[2], &objs[3], &objs[4], &objs[5], &objs[6], &objs[7],
                          &objs[8], &objs[9], &objs[10], &objs[11], &objs[12], &objs[13], &objs[14], &n))
        return NULL;
    static const char *const names[PROBLEM_ARRAYS + 3] = {PROBLEM_ARRAY_NAMES, "dash", "configs", "starts"};
    Py_buffer views[PROBLEM_ARRAYS + 3];
    Problem P;
    PyObject *result = NULL;
    int got = open_buffers(objs, names, PROBLEM_ARRAYS + 3, views);
    if (got < PROBLEM_ARRAYS + 3
        || problem_of(&P, n_att, n_dof, n_h, string, tension_model, views, views[12].buf) != 0)
        goto done;
    if (n < 1 || n > MAX_MODES) {
        PyErr_SetString(PyExc_ValueError, "refine: the number of roots must be 1 ... 512");
        goto done;
    }
    const long long *configs = views[13].buf;
    const cplx *starts = views[14].buf;
    Py_ssize_t n_cfg = views[13].len / (Py_ssize_t)sizeof(long long);
    if (views[14].len != n_cfg * n * (Py_ssize_t)sizeof(cplx)) {
        PyErr_SetString(PyExc_ValueError, "refine: starts must hold n roots per configuration");
        goto done;
    }
    PyObject *out = PyBytes_FromStringAndSize(NULL, n_cfg * n * (Py_ssize_t)sizeof(cplx));
    PyObject *status = PyBytes_FromStringAndSize(NULL, n_cfg * (Py_ssize_t)sizeof(int));
    if (!out || !status) { Py_XDECREF(out); Py_XDECREF(status); goto done; }
    cplx *s = (cplx *)PyBytes_AS_STRING(out);
    int *st = (int *)PyBytes_AS_STRING(status);
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = 0; i < n_cfg; i++)
        st[i] = refine_config(&P, configs[i], starts + i * n, n, s + i * n);
    Py_END_ALLOW_THREADS
    result = Py_BuildValue("NN", out, status);
done:
    close_buffers(views, got);
    return result;
}

static PyMethodDef methods[] = {
    {"solve", py_solve, METH_VARARGS, "Complex eigenvalues (rad/s) of damped configurations, with a status each."},
    {"refine", py_refine, METH_VARARGS, "Complex eigenvalues (rad/s) refined from a nearby configuration's, with a status each."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_damped_kernel", NULL, -1, methods};

PyMODINIT_FUNC PyInit__damped_kernel(void) { return PyModule_Create(&module); }
