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
 * tests compare the two.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <complex.h>
#include <math.h>
#include <string.h>

#define MAX_DOF 64
#define SECANT_RTOL 1e-10
#define SECANT_ITER 40
#define START 0.01
#define GROWTH 4.0
#define MIN_RATIO (1 + 1e-6)
#define DUPLICATE 1e-8
#define NEAR 16
#define MAX_MODES 512
#define MAX_DAMPING 0.5
#define JUMP 0.25
#define MAX_ARG_STEP (M_PI / 4)
#define MAX_CONTOUR_POINTS 200000
#define PER_EDGE 32

typedef double complex cplx;

typedef struct {
    int n_att, n_seg, n_dof, n_h, string, tension_model; /* 0 none, 1 uniform, 2 per-segment */
    const long long *v_dof, *t_dof, *h_dof;
    const double *length, *m, *EI, *H, *w, *seg_len, *masses, *kconst, *scale, *dash;
} Problem;

/* sin z and cos z from one complex exponential (|Im z| stays far below overflow on the contours). */
static void sin_cos(cplx z, cplx *s, cplx *c) {
    cplx e = cexp(I * z), r = 1.0 / e;
    *s = (e - r) / (2.0 * I);
    *c = 0.5 * (e + r);
}

/* x cos x − sin x, given sin x and cos x, without cancellation near 0. */
static cplx c_cos_minus_sin(cplx x, cplx sn, cplx cs) {
    cplx x2 = x * x;
    if (cabs(x) < 0.1) return x * x2 * (-1.0 / 3 + x2 * (1.0 / 30 + x2 * (-1.0 / 840 + x2 / 45360)));
    return x * cs - sn;
}

/* x − tanh x, given tanh x, without cancellation near 0. */
static cplx c_minus_tanh(cplx x, cplx th) {
    cplx x2 = x * x;
    if (cabs(x) < 0.1) return x * x2 * (1.0 / 3 + x2 * (-2.0 / 15 + x2 * (17.0 / 315 - x2 * 62.0 / 2835)));
    return x - th;
}

static cplx c_minus_tan(cplx x) {
    cplx x2 = x * x;
    if (cabs(x) < 0.1) return -x * x2 * (1.0 / 3 + x2 * (2.0 / 15 + x2 * (17.0 / 315 + x2 * 62.0 / 2835)));
    return x - ctan(x);
}

static void beam_segment(double L, double EI, double H, double m, cplx omega, cplx Ke[16], cplx force[4], cplx *R) {
    double half = 0.5 * L;
    double a_ = H / (2.0 * EI);
    cplx b_ = m * omega * omega / EI;
    cplx root = csqrt(a_ * a_ + b_);
    cplx p2 = a_ + root, q2 = b_ / p2;
    cplx p = csqrt(p2), q = csqrt(q2);
    cplx pl = p * half, ql = q * half;
    cplx T = ctanh(pl), s, c;
    sin_cos(ql, &s, &c);
    cplx ppqq = p2 + q2, pq = p * q;
    cplx xcs = c_cos_minus_sin(ql, s, c), xt = c_minus_tanh(pl, T);
    cplx n_sym = q * s + p * T * c, n_anti = p * xcs - q * c * xt;
    cplx k1 = EI / n_sym, k2 = EI / n_anti;
    cplx a = -k1 * pq * T * s * ppqq, b = -k1 * pq * n_anti, d = k1 * c * ppqq;
    cplx e = -k2 * pq * c * ppqq, f = k2 * pq * n_sym, h = -k2 * T * s * ppqq;
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
}

static void string_segment(double L, double H, double m, cplx omega, cplx Ke[4], cplx force[2], cplx *R) {
    double half = 0.5 * L;
    cplx q = omega * sqrt(m / H);
    cplx ql2 = 2.0 * q * half;
    cplx sn, cs;
    sin_cos(ql2, &sn, &cs);
    cplx diag = H * q * cs / sn, off = -H * q / sn;
    Ke[0] = Ke[3] = diag;
    Ke[1] = Ke[2] = off;
    force[0] = force[1] = diag + off;
    *R = 2.0 * H * q * c_minus_tan(q * half);
}

/* Number of clamped–clamped segment frequencies below a real ω (the poles of det K): J0. */
static int clamped_count(const Problem *P, long long cfg, double omega) {
    int J0 = 0;
    double m = P->m[cfg], H = P->H[cfg], EI = P->EI[cfg];
    for (int j = 0; j < P->n_seg; j++) {
        double L = P->seg_len[cfg * P->n_seg + j];
        if (P->string) {
            double n = ceil(omega * sqrt(m / H) * L / M_PI) - 1;
            J0 += n > 0 ? (int)n : 0;
            continue;
        }
        double a_ = H / (2.0 * EI), b_ = m * omega * omega / EI;
        double p2 = a_ + sqrt(a_ * a_ + b_), q2 = b_ / p2, p = sqrt(p2), q = sqrt(q2);
        double pL = p * L, qL = q * L, ex = exp(-pL);
        double delta = 2 * p * q * (ex * 2.0 / (1.0 + ex * ex) - cos(qL)) + (p2 - q2) * tanh(pL) * sin(qL);
        double i = floor(qL / M_PI);
        if (i < 1) continue;
        double parity = fmod(i, 2.0) == 0.0 ? 1.0 : -1.0;
        J0 += (int)(i - 1) + (((delta > 0) - (delta < 0)) == parity);
    }
    return J0;
}

/* det of the scaled K(s) of configuration cfg with the dashpots times t. */
static cplx cdet(const Problem *P, long long cfg, cplx s, double t) {
    int nd = P->n_dof, ns = P->n_seg;
    cplx K[MAX_DOF * MAX_DOF];
    for (int i = 0; i < nd * nd; i++) K[i] = P->kconst[cfg * nd * nd + i];
    double m = P->m[cfg], H = P->H[cfg], EI = P->EI[cfg];
    cplx omega = -I * s;
    cplx gamma = P->w[cfg] / (H * m * omega * omega);
    for (int j = 0; j < ns; j++) {
        cplx Ke[16], force[4], R;
        long long dofs[4];
        int ne;
        double L = P->seg_len[cfg * ns + j];
        if (P->string) {
            ne = 2;
            string_segment(L, H, m, omega, Ke, force, &R);
            dofs[0] = P->v_dof[j]; dofs[1] = P->v_dof[j + 1];
        } else {
            ne = 4;
            beam_segment(L, EI, H, m, omega, Ke, force, &R);
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
                cplx v = -gamma * force[r];
                K[dofs[r] * nd + hj] += v;
                K[hj * nd + dofs[r]] += v;
            }
            K[hj * nd + hj] += gamma * gamma * R;
        }
    }
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
        cplx guess = have_prev ? s + (s - prev_s) * (log(t1 / t) / log(t / prev_t)) : s + first * (t1 - t);
        if (secant(P, cfg, t1, s, cdet(P, cfg, s, t1), guess, &s1) != 0 || cabs(s1 - s) > reach) {
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

/* Each undamped root omega[k] followed to t = 1; 0, or −(k+1) for a mode that could not be followed. */
static int follow(const Problem *P, long long cfg, const double *omega, const double *pinned, int n, cplx *out) {
    for (int k = 0; k < n; k++) {
        double below = omega[k] - (k > 0 ? omega[k - 1] : 0.0);
        double above = k + 1 < n ? omega[k + 1] - omega[k] : (n > 1 ? omega[k] - omega[k - 1] : omega[k]);
        double reach = JUMP * (below < above ? below : above);
        cplx s0 = I * omega[k], s;
        double h = 1e-7 * omega[k];
        cplx f1 = cdet(P, cfg, s0, 1.0);
        cplx first = -f1 * 2 * h / (cdet(P, cfg, s0 + h, 0.0) - cdet(P, cfg, s0 - h, 0.0));
        cplx guess = s0 + 1.0 / (1.0 / first + 1.0 / (I * (pinned[k] - omega[k])));
        if (secant(P, cfg, 1.0, s0, f1, guess, &s) != 0 || cabs(s - guess) > reach)
            if (follow_in_steps(P, cfg, s0, first, reach, &s) != 0) return -(k + 1);
        int fell = 0;
        for (int j = 0; j < k; j++) fell |= cabs(out[j] - s) <= DUPLICATE * cabs(s);
        if (fell) {  /* another path's root (a near crossing): the nearby roots divided out, from the start */
            cplx near[MAX_MODES];
            int n_near = 0;
            for (int j = 0; j < k && n_near < MAX_MODES; j++)
                if (cabs(out[j] - s0) < NEAR * reach) near[n_near++] = out[j];
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
            if (!ok) return -(k + 1);
        }
        out[k] = s;
    }
    return 0;
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

/* Turns of det K around 0 along the quadrilateral Im s in [lo, hi], −slope Im s < Re s < right
 * (counter-clockwise); 0 or −1. */
static int winding(const Problem *P, long long cfg, double lo, double hi, double slope, double right, int *turns) {
    cplx corners[5] = {right + I * lo, right + I * hi, (-slope + I) * hi, (-slope + I) * lo, right + I * lo};
    Contour C = {P, cfg, 0};
    double total = 0.0;
    cplx z0 = corners[0], f0 = cdet(P, cfg, z0, 1.0);
    cplx z = z0, fz = f0;
    for (int e = 0; e < 4; e++)
        for (int k = 1; k <= PER_EDGE; k++) {
            cplx zn = (e == 3 && k == PER_EDGE) ? z0 : corners[e] + (corners[e + 1] - corners[e]) * ((double)k / PER_EDGE);
            cplx fn = (e == 3 && k == PER_EDGE) ? f0 : cdet(P, cfg, zn, 1.0);
            if (phase(&C, z, fz, zn, fn, &total) != 0) return -1;
            z = zn; fz = fn;
        }
    *turns = (int)lround(total / (2 * M_PI));
    return 0;
}

/* Status: 0 ok, 1 a path failed, 2 modes unordered at the band's top, 3 the contour did not resolve,
 * 4 the count disagrees (a mode lost), 5 two paths on one root. */
static int solve_config(const Problem *P, long long cfg, const double *omega, const double *pinned, int n_modes,
                        int certify, cplx *s) {
    int n = n_modes + 1;
    if (follow(P, cfg, omega, pinned, n, s) != 0) return 1;
    if (!certify) return 0;
    double top = cimag(s[0]), above = cimag(s[n_modes]);
    for (int k = 1; k < n_modes; k++) if (cimag(s[k]) > top) top = cimag(s[k]);
    if (!(above > top)) return 2;
    double lo = 0.25 * omega[0], hi = 0.5 * (top + above), right = 0.05 * omega[0];
    double slope = MAX_DAMPING / sqrt(1 - MAX_DAMPING * MAX_DAMPING);
    int inside = 0;
    for (int k = 0; k < n; k++)
        if (cimag(s[k]) > lo && cimag(s[k]) < hi && creal(s[k]) < right && creal(s[k]) > -slope * cimag(s[k]))
            inside++;
    int turns;
    if (winding(P, cfg, lo, hi, slope, right, &turns) != 0) return 3;
    int zeros = turns + clamped_count(P, cfg, hi) - clamped_count(P, cfg, lo);
    if (zeros != inside) return 4;
    for (int a = 0; a < n; a++)
        for (int b = a + 1; b < n; b++)
            if (cabs(s[a] - s[b]) < 1e-9 * hi) return 5;
    return 0;
}

static int get_buffer(PyObject *obj, Py_buffer *view, const char *name) {
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS) < 0) {
        PyErr_Format(PyExc_TypeError, "%s: a contiguous buffer is required", name);
        return -1;
    }
    return 0;
}

/* solve(topology ints, arrays..., configs, omega (n_cfg_all × (n_modes+1)), pinned (configs × (n_modes+1)),
 *       n_modes, certify)
 * -> (bytes of complex128 s, configs × (n_modes+1)), bytes of int32 status per config) */
static PyObject *py_solve(PyObject *self, PyObject *args) {
    int n_att, n_dof, n_h, string, tension_model, n_modes, certify;
    PyObject *objs[16];
    if (!PyArg_ParseTuple(args, "iiiii" "OOOOOOOOOOOOOOOO" "ii", &n_att, &n_dof, &n_h, &string, &tension_model,
                          &objs[0], &objs[1], &objs[2], &objs[3], &objs[4], &objs[5], &objs[6], &objs[7],
                          &objs[8], &objs[9], &objs[10], &objs[11], &objs[12], &objs[13], &objs[14], &objs[15],
                          &n_modes, &certify))
        return NULL;
    if (n_dof > MAX_DOF) {
        PyErr_SetString(PyExc_ValueError, "too many degrees of freedom for the compiled kernel");
        return NULL;
    }
    static const char *names[16] = {"v_dof", "t_dof", "h_dof", "length", "m", "EI", "H", "w", "seg_len",
                                    "masses", "kconst", "scale", "dash", "configs", "omega", "pinned"};
    Py_buffer views[16];
    int got = 0;
    PyObject *result = NULL;
    for (; got < 16; got++)
        if (get_buffer(objs[got], &views[got], names[got]) < 0) goto done;
    Problem P = {n_att, n_att + 1, n_dof, n_h, string, tension_model,
                 views[0].buf, views[1].buf, views[2].buf,
                 views[3].buf, views[4].buf, views[5].buf, views[6].buf, views[7].buf, views[8].buf,
                 views[9].buf, views[10].buf, views[11].buf, views[12].buf};
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
    for (int i = 0; i < got; i++) PyBuffer_Release(&views[i]);
    return result;
}

static PyMethodDef methods[] = {
    {"solve", py_solve, METH_VARARGS, "Complex eigenvalues (rad/s) of damped configurations, with a status each."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_damped_kernel", NULL, -1, methods};

PyMODINIT_FUNC PyInit__damped_kernel(void) { return PyModule_Create(&module); }
