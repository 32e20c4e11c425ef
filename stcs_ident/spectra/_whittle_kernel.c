/*
 * Compiled kernel of the Whittle fit's linear terms (optional): whittle.py's whittle_linear_many, one
 * candidate at a time. For each candidate's real basis (bins × q columns) and the band's periodogram, the
 * linear coefficients by damped Fisher scoring (iteratively reweighted least squares) from the flat mean, the
 * powers held >= 0 by dropping the most negative column in turn, each step halved until the likelihood does
 * not fall (at most 20 times; a candidate whose step cannot be made to stops), and the -log-likelihood
 * sum(log E + P / E) (P the periodogram), infinite where a mean is not positive.
 *
 * It exists because the profile likelihood's grids and the fits' start grids are hundreds of candidates of
 * a few hundred bins and five to eight columns: numpy's per-call overhead and its temporaries over the
 * candidates' stacked arrays cost more than the arithmetic. whittle.py stays the reference (STCS_IDENT_NUMPY=1
 * runs it) and the tests compare the two. Each candidate's arithmetic is its own, in a fixed order: the result
 * does not depend on how many candidates are evaluated together, nor on threads (a BLAS product's last bits
 * do, which made a Dask run's tensions differ from a local run's by 1e-9).
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#ifndef _WIN32
#include <pthread.h>
#endif

#define MAX_COLUMNS 32
#define HALVINGS 20
#define RIDGE 1e-12

/* -log-likelihood of the mean e against the periodogram P over m bins: +inf where a mean is <= 0, NaN
 * propagated (as whittle.py's _neg_log_likelihood_many); `inv` gets 1 / e (the next step's weights). */
static double neg_log_likelihood(const double *e, const double *P, Py_ssize_t m, double *inv) {
    double total = 0.0;
    int bad = 0;
    for (Py_ssize_t k = 0; k < m; k++) {
        double r = 1.0 / e[k];
        inv[k] = r;
        if (e[k] <= 0.0)
            bad = 1;
        else
            total += log(e[k]) + P[k] * r;
    }
    return bad ? INFINITY : total;
}

static void mean_of(const double *B, const double *lin, Py_ssize_t m, int q, double *e) {
    for (Py_ssize_t k = 0; k < m; k++) {
        const double *row = B + k * q;
        double s = 0.0;
        for (int j = 0; j < q; j++) s += row[j] * lin[j];
        e[k] = s;
    }
}

/* x = A⁻¹ b for a q × q matrix (row-major, overwritten) by LU with partial pivoting; NaN where a pivot is 0. */
static void solve(double *A, double *b, int q, double *x) {
    for (int c = 0; c < q; c++) {
        int p = c;
        for (int r = c + 1; r < q; r++)
            if (fabs(A[r * q + c]) > fabs(A[p * q + c])) p = r;
        if (p != c) {
            for (int j = 0; j < q; j++) {
                double t = A[c * q + j]; A[c * q + j] = A[p * q + j]; A[p * q + j] = t;
            }
            double t = b[c]; b[c] = b[p]; b[p] = t;
        }
        double pivot = A[c * q + c];
        if (pivot == 0.0) {
            for (int j = 0; j < q; j++) x[j] = NAN;
            return;
        }
        for (int r = c + 1; r < q; r++) {
            double f = A[r * q + c] / pivot;
            if (f == 0.0) continue;
            for (int j = c; j < q; j++) A[r * q + j] -= f * A[c * q + j];
            b[r] -= f * b[c];
        }
    }
    for (int r = q - 1; r >= 0; r--) {
        double s = b[r];
        for (int j = r + 1; j < q; j++) s -= A[r * q + j] * x[j];
        x[r] = s / A[r * q + r];
    }
}

/* min ||w (B c − P)|| with c >= 0 where `nonnegative`, by dropping the most negative bounded column in turn
 * (whittle.py's _weighted_least_squares_many for one candidate: a dropped column's row and column of the
 * scaled normal matrix zero but for the ridge, its coefficient 0). */
static void weighted_least_squares(const double *B, const double *P, const double *w, const unsigned char *nonneg,
                                   Py_ssize_t m, int q, double *coef) {
    double full[MAX_COLUMNS * MAX_COLUMNS] = {0}, rhs[MAX_COLUMNS] = {0}, a[MAX_COLUMNS];
    for (Py_ssize_t k = 0; k < m; k++) {
        const double *row = B + k * q;
        double wk = w[k], bk = P[k] * wk;
        for (int i = 0; i < q; i++) a[i] = row[i] * wk;
        for (int i = 0; i < q; i++) {
            double ai = a[i];
            for (int j = i; j < q; j++) full[i * q + j] += ai * a[j];
            rhs[i] += ai * bk;
        }
    }
    for (int i = 0; i < q; i++)
        for (int j = 0; j < i; j++) full[i * q + j] = full[j * q + i];
    unsigned char free_[MAX_COLUMNS], bounded[MAX_COLUMNS];
    for (int j = 0; j < q; j++) { free_[j] = 1; bounded[j] = nonneg[j]; coef[j] = 0.0; }
    double normal[MAX_COLUMNS * MAX_COLUMNS], scale[MAX_COLUMNS], r[MAX_COLUMNS], x[MAX_COLUMNS];
    for (int pass = 0; pass < q; pass++) {
        for (int i = 0; i < q; i++) {
            double d = free_[i] ? full[i * q + i] : 0.0;
            scale[i] = sqrt(d > DBL_MIN ? d : DBL_MIN);
        }
        for (int i = 0; i < q; i++) {
            for (int j = 0; j < q; j++)
                normal[i * q + j] = (free_[i] && free_[j] ? full[i * q + j] : 0.0) / (scale[i] * scale[j]);
            normal[i * q + i] += RIDGE;
            r[i] = (free_[i] ? rhs[i] : 0.0) / scale[i];
        }
        solve(normal, r, q, x);
        int worst = -1;
        double lowest = 0.0;
        for (int j = 0; j < q; j++) {
            coef[j] = x[j] / scale[j] * (double)free_[j];
            double candidate = bounded[j] ? coef[j] : 0.0;
            if (isnan(candidate)) { worst = -2; break; } /* numpy's argmin stops at a NaN: no column dropped */
            if (worst == -1 || candidate < lowest) { worst = j; lowest = candidate; }
        }
        if (worst == -2) {
            for (int j = 0; j < q; j++) coef[j] = x[j] / scale[j] * (double)free_[j];
            break;
        }
        if (!(lowest < 0.0)) break;
        free_[worst] = bounded[worst] = 0;
    }
}

/* One candidate: its coefficients (q) and -log-likelihood; work holds 4 m doubles. */
static double fit_candidate(const double *B, const double *P, const unsigned char *nonneg, Py_ssize_t m, int q,
                            int iterations, double level, double *lin, double *work) {
    double *e = work, *trial_e = work + m, *w = work + 2 * m, *trial_w = work + 3 * m;
    double target[MAX_COLUMNS], step[MAX_COLUMNS], trial[MAX_COLUMNS];
    for (int j = 0; j < q; j++) lin[j] = 0.0;
    lin[q - 2] = level;
    if (nonneg[q - 1]) lin[q - 1] = level; /* the background as two nonnegative edge ramps: both at the mean */
    mean_of(B, lin, m, q, e);
    double nll = neg_log_likelihood(e, P, m, w);
    for (int it = 0; it < iterations; it++) {
        weighted_least_squares(B, P, w, nonneg, m, q, target); /* w = 1 / e of the accepted mean */
        for (int j = 0; j < q; j++) step[j] = target[j] - lin[j];
        int accepted = 0;
        for (int h = 0; h < HALVINGS; h++) {
            for (int j = 0; j < q; j++) trial[j] = lin[j] + step[j];
            mean_of(B, trial, m, q, trial_e);
            double trial_nll = neg_log_likelihood(trial_e, P, m, trial_w);
            if (trial_nll <= nll) {
                memcpy(lin, trial, q * sizeof(double));
                double *t = e; e = trial_e; trial_e = t;
                t = w; w = trial_w; trial_w = t;
                nll = trial_nll;
                accepted = 1;
                break;
            }
            for (int j = 0; j < q; j++) step[j] /= 2;
        }
        if (!accepted) break;
    }
    return nll;
}

/* The rotations of y = ω − φ and of N y: cos, sin, 2 sin²(·/2) of each (whittle.py's _turns). */
static void rotations(double y, double n, double *t) {
    double yn = n * y, h = sin(0.5 * y), hn = sin(0.5 * yn);
    t[0] = cos(y); t[1] = sin(y); t[2] = 2.0 * h * h;
    t[3] = cos(yn); t[4] = sin(yn); t[5] = 2.0 * hn * hn;
}

/* The pole's constants: exp and expm1 of a and of N a (a = Re z = −σΔt). */
typedef struct {
    double grow, grow_n, em1, em1_n, n;
} Pole;

static Pole pole_of(double a, double n) {
    Pole z = {exp(a), exp(n * a), expm1(a), expm1(n * a), n};
    return z;
}

/* H(u) = 2G(u) − 1 at one bin, G(u) = 1/(1 − u) − u (1 − uᴺ) / (N (1 − u)²), u = exp(z − iφ), from the bin's
 * rotations `t` (whittle.py's _fejer: exp and expm1 of x + iy written out, free of cancellation near u = 1),
 * into H[0] + i H[1]; and, where `dH` is given, dH/dz = 2 dG/du · u into dH[0] + i dH[1]. */
static void fejer_bin(const double *t, const Pole *z, double *H, double *dH) {
    double n = z->n;
    /* 1 − u = x + iy, its reciprocal r = (x − iy) / |1 − u|², then g = r − u (1 − uᴺ) r² / N */
    double x = t[2] - z->em1 * t[0], y = -z->grow * t[1], d = 1.0 / (x * x + y * y);
    double rr = x * d, ri = -y * d;
    double ur = z->grow * t[0], ui = z->grow * t[1];                    /* u */
    double tr = t[5] - z->em1_n * t[3], ti = -z->grow_n * t[4];         /* 1 − uᴺ */
    double pr = ur * tr - ui * ti, pi = ur * ti + ui * tr;              /* u (1 − uᴺ) */
    double r2r = rr * rr - ri * ri, r2i = 2.0 * rr * ri;                /* r² */
    double gr = rr - (pr * r2r - pi * r2i) / n, gi = ri - (pr * r2i + pi * r2r) / n;
    H[0] = 2.0 * gr - 1.0;
    H[1] = 2.0 * gi;
    if (!dH) return;
    /* dG/du = r² − (1 − uᴺ − N uᴺ) r² / N − 2 u (1 − uᴺ) r³ / N */
    double unr = z->grow_n * t[3], uni = z->grow_n * t[4];              /* uᴺ */
    double r3r = r2r * rr - r2i * ri, r3i = r2r * ri + r2i * rr;        /* r³ */
    double sr = tr - n * unr, si = ti - n * uni;
    double dgr = r2r - (sr * r2r - si * r2i) / n - 2.0 * (pr * r3r - pi * r3i) / n;
    double dgi = r2i - (sr * r2i + si * r2r) / n - 2.0 * (pr * r3i + pi * r3r) / n;
    dH[0] = 2.0 * (dgr * ur - dgi * ui);
    dH[1] = 2.0 * (dgr * ui + dgi * ur);
}

/* The mode's two columns of one pole z = a + iω (a = −σΔt, ω = 2π f Δt) over the bins' phases φ_k: Re H + Im H
 * and Re H − Im H (:c:func:`fejer_bin`), into the first two columns of the rows of `basis` (m × q). The
 * rotations depend on ω alone: `turns` (6 m doubles) holds them for `omega_done` and is recomputed only for
 * another ω. */
static void mode_columns(double a, double omega, const double *phase, Py_ssize_t m, double n, double *turns,
                         double *omega_done, int q, double *basis) {
    if (!(omega == *omega_done)) {
        for (Py_ssize_t k = 0; k < m; k++) rotations(omega - phase[k], n, turns + 6 * k);
        *omega_done = omega;
    }
    Pole z = pole_of(a, n);
    for (Py_ssize_t k = 0; k < m; k++) {
        double H[2];
        fejer_bin(turns + 6 * k, &z, H, NULL);
        basis[k * q] = H[0] + H[1];
        basis[k * q + 1] = H[0] - H[1];
    }
}

/* The first n objects' buffers (C-contiguous) into views; how many were opened (n, or fewer with an error set). */
static int open_views(PyObject *const *objs, int n, Py_buffer *views) {
    for (int k = 0; k < n; k++)
        if (PyObject_GetBuffer(objs[k], &views[k], PyBUF_C_CONTIGUOUS) < 0) return k;
    return n;
}

static void close_views(Py_buffer *views, int n) {
    for (int k = 0; k < n; k++) PyBuffer_Release(&views[k]);
}

/* A run of consecutive rows of a grid, fitted by one thread with its own buffers. */
typedef struct {
    const double *theta, *phase, *fixed, *P;
    const unsigned char *nonneg;
    Py_ssize_t m, begin, end;
    int q, iterations, failed;
    double n, dt, level;
    double *L, *N;
} Rows;

static void *fit_rows(void *arg) {
    Rows *r = arg;
    Py_ssize_t m = r->m;
    int q = r->q;
    double *work = malloc((4 * m + 6 * m + m * q) * sizeof(double));
    if (!work) {
        r->failed = 1;
        return NULL;
    }
    double *turns = work + 4 * m, *basis = work + 10 * m, omega_done = NAN;
    for (Py_ssize_t k = 0; k < m; k++)
        for (int j = 2; j < q; j++) basis[k * q + j] = r->fixed[k * (q - 2) + j - 2];
    for (Py_ssize_t i = r->begin; i < r->end; i++) {
        mode_columns(-r->theta[2 * i + 1] * r->dt, 2.0 * M_PI * r->theta[2 * i] * r->dt, r->phase, m, r->n, turns,
                     &omega_done, q, basis);
        r->N[i] = fit_candidate(basis, r->P, r->nonneg, m, q, r->iterations, r->level, r->L + i * q, work);
    }
    free(work);
    return NULL;
}

#define MAX_THREADS 16

/* grid(thetas (c × 2: f Hz, σ 1/s), phase (m), n_samples, dt, fixed (m × (q − 2)), periodogram (m),
 *      nonnegative (q uint8), iterations, threads) -> as linear_many, of the bases [mode columns of θ, fixed]:
 *      whittle.py's whittle_linear_many(designs(thetas, problem), ...) without the bases stacked in memory. The
 *      rows are split into `threads` runs of consecutive rows (POSIX threads; one where there are none): a row's
 *      result is its own arithmetic's, whichever thread fits it. */
static PyObject *py_grid(PyObject *self, PyObject *args) {
    PyObject *objs[5];
    Py_ssize_t n_samples;
    double dt;
    int iterations, threads;
    if (!PyArg_ParseTuple(args, "OOndOOOii", &objs[0], &objs[1], &n_samples, &dt, &objs[2], &objs[3], &objs[4],
                          &iterations, &threads))
        return NULL;
    Py_buffer views[5];
    PyObject *result = NULL;
    int got = open_views(objs, 5, views);
    if (got < 5) goto done;
    Py_ssize_t c = views[0].len / (2 * (Py_ssize_t)sizeof(double));
    Py_ssize_t m = views[1].len / (Py_ssize_t)sizeof(double);
    int q = (int)views[4].len;
    if (q < 2 || q > MAX_COLUMNS || m < 1 || views[3].len != m * (Py_ssize_t)sizeof(double)
        || views[2].len != m * (q - 2) * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "grid: phase, fixed (bins x q-2) and periodogram must agree, q 2..32");
        goto done;
    }
    const double *Iv = views[3].buf;
    PyObject *lin = PyBytes_FromStringAndSize(NULL, c * q * (Py_ssize_t)sizeof(double));
    PyObject *nll = PyBytes_FromStringAndSize(NULL, c * (Py_ssize_t)sizeof(double));
    if (!lin || !nll) {
        Py_XDECREF(lin); Py_XDECREF(nll);
        goto done;
    }
    double level = 0.0;
    for (Py_ssize_t k = 0; k < m; k++) level += Iv[k];
    level /= (double)m;
#ifdef _WIN32
    threads = 1;
#endif
    if (threads > MAX_THREADS) threads = MAX_THREADS;
    if (threads > c) threads = (int)c;
    if (threads < 1) threads = 1;
    Rows rows[MAX_THREADS];
    for (int t = 0; t < threads; t++) {
        Rows r = {views[0].buf, views[1].buf, views[2].buf, Iv, views[4].buf, m, c * t / threads,
                  c * (t + 1) / threads, q, iterations, 0, (double)n_samples, dt, level,
                  (double *)PyBytes_AS_STRING(lin), (double *)PyBytes_AS_STRING(nll)};
        rows[t] = r;
    }
    int failed = 0;
    Py_BEGIN_ALLOW_THREADS
#ifndef _WIN32
    pthread_t handles[MAX_THREADS];
    int started[MAX_THREADS] = {0};
    for (int t = 1; t < threads; t++) started[t] = pthread_create(&handles[t], NULL, fit_rows, &rows[t]) == 0;
    fit_rows(&rows[0]);
    for (int t = 1; t < threads; t++) {
        if (started[t])
            pthread_join(handles[t], NULL);
        else
            fit_rows(&rows[t]); /* a thread that could not start: its rows here */
    }
#else
    fit_rows(&rows[0]);
#endif
    Py_END_ALLOW_THREADS
    for (int t = 0; t < threads; t++) failed |= rows[t].failed;
    if (failed) {
        Py_DECREF(lin); Py_DECREF(nll);
        PyErr_NoMemory();
        goto done;
    }
    result = Py_BuildValue("NN", lin, nll);
done:
    close_views(views, got);
    return result;
}

/* ---- The one-pole fit: Fisher scoring over (f, σ) and the linear terms (ambient_fit.py's fisher_scoring with its
 * _expected and _scoring_step, whose reference they stay). ---- */

#define MAX_PARAMETERS (MAX_COLUMNS + 2)
#define STEP_HALVINGS 30
#define CONVERGED 1e-4

/* Eigen-decomposition of a symmetric p × p matrix (row-major, destroyed) by cyclic Jacobi rotations:
 * eigenvalues in `value`, eigenvectors in the columns of `vector`. */
static void symmetric_eigen(double *A, int p, double *value, double *vector) {
    for (int i = 0; i < p; i++)
        for (int j = 0; j < p; j++) vector[i * p + j] = i == j ? 1.0 : 0.0;
    for (int sweep = 0; sweep < 60; sweep++) {
        double off = 0.0, diag = 0.0;
        for (int i = 0; i < p; i++) {
            diag += A[i * p + i] * A[i * p + i];
            for (int j = i + 1; j < p; j++) off += A[i * p + j] * A[i * p + j];
        }
        if (!(off > 1e-32 * diag)) break;
        for (int i = 0; i < p; i++)
            for (int j = i + 1; j < p; j++) {
                double aij = A[i * p + j];
                if (aij == 0.0) continue;
                double theta = (A[j * p + j] - A[i * p + i]) / (2.0 * aij);
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), sn = t * c;
                for (int k = 0; k < p; k++) { /* columns i, j */
                    double x = A[k * p + i], y = A[k * p + j];
                    A[k * p + i] = c * x - sn * y;
                    A[k * p + j] = sn * x + c * y;
                }
                for (int k = 0; k < p; k++) { /* rows i, j */
                    double x = A[i * p + k], y = A[j * p + k];
                    A[i * p + k] = c * x - sn * y;
                    A[j * p + k] = sn * x + c * y;
                }
                for (int k = 0; k < p; k++) {
                    double x = vector[k * p + i], y = vector[k * p + j];
                    vector[k * p + i] = c * x - sn * y;
                    vector[k * p + j] = sn * x + c * y;
                }
            }
    }
    for (int i = 0; i < p; i++) value[i] = A[i * p + i];
}

/* The least-squares solution of the symmetric system A x = b (numpy's lstsq with rcond: singular values below
 * rcond times the largest left out), from its eigen-decomposition (|λ| are its singular values). */
static void symmetric_lstsq(double *A, const double *b, int p, double rcond, double *x) {
    double value[MAX_PARAMETERS], vector[MAX_PARAMETERS * MAX_PARAMETERS];
    symmetric_eigen(A, p, value, vector);
    double largest = 0.0;
    for (int i = 0; i < p; i++) largest = fabs(value[i]) > largest ? fabs(value[i]) : largest;
    for (int k = 0; k < p; k++) x[k] = 0.0;
    for (int i = 0; i < p; i++) {
        if (!(fabs(value[i]) > rcond * largest)) continue;
        double proj = 0.0;
        for (int k = 0; k < p; k++) proj += vector[k * p + i] * b[k];
        proj /= value[i];
        for (int k = 0; k < p; k++) x[k] += proj * vector[k * p + i];
    }
}

/* The band: its bins, fixed columns and bounds. */
typedef struct {
    const double *phase, *fixed, *P;
    const unsigned char *nonneg; /* of the q linear terms */
    Py_ssize_t m;
    int q; /* linear terms: the mode's two, then the fixed columns */
    double n, dt;
} Band;

/* The expected periodogram at θ = (f, σ, linear terms) and its gradient (m × (2 + q), row-major). */
static void expected(const Band *b, const double *theta, double *mean, double *grad) {
    int q = b->q, p = q + 2;
    double omega = 2.0 * M_PI * theta[0] * b->dt, wdt = 2.0 * M_PI * b->dt;
    Pole z = pole_of(-theta[1] * b->dt, b->n);
    double c0 = theta[2], c1 = theta[3];
    for (Py_ssize_t k = 0; k < b->m; k++) {
        double t[6], H[2], dH[2];
        rotations(omega - b->phase[k], b->n, t);
        fejer_bin(t, &z, H, dH);
        /* d/df = dH · 2πiΔt, d/dσ = dH · (−Δt) */
        double dfr = -dH[1] * wdt, dfi = dH[0] * wdt, dsr = -dH[0] * b->dt, dsi = -dH[1] * b->dt;
        double *g = grad + k * p;
        double col0 = H[0] + H[1], col1 = H[0] - H[1];
        g[0] = (dfr + dfi) * c0 + (dfr - dfi) * c1;
        g[1] = (dsr + dsi) * c0 + (dsr - dsi) * c1;
        g[2] = col0;
        g[3] = col1;
        double e = col0 * c0 + col1 * c1;
        const double *f = b->fixed + k * (q - 2);
        for (int j = 0; j < q - 2; j++) {
            g[4 + j] = f[j];
            e += f[j] * theta[4 + j];
        }
        mean[k] = e;
    }
}

/* The scoring step with the powers at zero held where the quadratic model wants them lower, released when its
 * gradient says the likelihood would fall with them (ambient_fit.py's _scoring_step). */
static void scoring_step(const double *theta, const double *score, const double *fisher, const unsigned char *nonneg,
                         int p, double *step) {
    unsigned char at_zero[MAX_PARAMETERS], held[MAX_PARAMETERS] = {0};
    double largest = 0.0;
    for (int i = 0; i < p; i++) largest = fabs(theta[i]) > largest ? fabs(theta[i]) : largest;
    for (int i = 0; i < p; i++) at_zero[i] = i >= 2 && nonneg[i - 2] && theta[i] <= 1e-12 * largest;
    for (int round = 0; round < 2 * p; round++) {
        int idx[MAX_PARAMETERS], nf = 0;
        for (int i = 0; i < p; i++)
            if (!held[i]) idx[nf++] = i;
        double sub[MAX_PARAMETERS * MAX_PARAMETERS], scale[MAX_PARAMETERS], rhs[MAX_PARAMETERS], x[MAX_PARAMETERS];
        for (int a = 0; a < nf; a++) {
            double dg = fisher[idx[a] * p + idx[a]];
            scale[a] = sqrt(dg > DBL_MIN ? dg : DBL_MIN);
        }
        for (int a = 0; a < nf; a++) {
            for (int c = 0; c < nf; c++) sub[a * nf + c] = fisher[idx[a] * p + idx[c]] / (scale[a] * scale[c]);
            rhs[a] = score[idx[a]] / scale[a];
        }
        symmetric_lstsq(sub, rhs, nf, 1e-12, x);
        for (int i = 0; i < p; i++) step[i] = 0.0;
        for (int a = 0; a < nf; a++) step[idx[a]] = x[a] / scale[a];
        int blocked = 0;
        for (int a = 0; a < nf; a++)
            if (at_zero[idx[a]] && step[idx[a]] < 0) { held[idx[a]] = 1; blocked = 1; }
        if (blocked) continue;
        int release = -1;
        double lowest = 0.0;
        for (int i = 0; i < p; i++) {
            if (!held[i]) continue;
            double gradient = -score[i];
            for (int j = 0; j < p; j++) gradient += fisher[i * p + j] * step[j];
            if (gradient < 0 && (release < 0 || gradient < lowest)) { release = i; lowest = gradient; }
        }
        if (release < 0) break;
        held[release] = 0;
    }
}

/* Fisher scoring from θ; returns 1 when converged (θ, its mean and gradient where it ended). */
static int scoring(const Band *b, double *theta, const double *limits, int max_iterations, double *mean, double *grad,
                   double *work) {
    int q = b->q, p = q + 2;
    Py_ssize_t m = b->m;
    double *trial_mean = work, *trial_grad = work + m, *inv = work + m + m * p; /* 1/E: not needed here */
    expected(b, theta, mean, grad);
    double nll = neg_log_likelihood(mean, b->P, m, inv);
    for (int it = 0; it < max_iterations; it++) {
        double score[MAX_PARAMETERS] = {0}, fisher[MAX_PARAMETERS * MAX_PARAMETERS] = {0}, step[MAX_PARAMETERS];
        for (Py_ssize_t k = 0; k < m; k++) {
            const double *g = grad + k * p;
            double r = 1.0 / mean[k], res = (b->P[k] - mean[k]) * r * r, gk[MAX_PARAMETERS];
            for (int i = 0; i < p; i++) {
                score[i] += g[i] * res;
                gk[i] = g[i] * r;
            }
            for (int i = 0; i < p; i++)
                for (int j = i; j < p; j++) fisher[i * p + j] += gk[i] * gk[j];
        }
        int finite = 1;
        for (int i = 0; i < p; i++) {
            for (int j = 0; j < i; j++) fisher[i * p + j] = fisher[j * p + i];
            finite &= isfinite(score[i]);
            for (int j = 0; j < p; j++) finite &= isfinite(fisher[i * p + j]);
        }
        if (!finite) return 0;
        scoring_step(theta, score, fisher, b->nonneg, p, step);
        int small = 1;
        for (int i = 0; i < p; i++) finite &= isfinite(step[i]);
        if (!finite) return 0;
        for (int i = 0; i < 2; i++) {
            double dg = fisher[i * p + i];
            small &= fabs(step[i]) * sqrt(dg > DBL_MIN ? dg : DBL_MIN) < CONVERGED;
        }
        if (small) return 1;
        int accepted = 0;
        for (int h = 0; h < STEP_HALVINGS; h++) {
            double trial[MAX_PARAMETERS];
            for (int i = 0; i < p; i++) trial[i] = theta[i] + step[i];
            for (int i = 2; i < p; i++)
                if (b->nonneg[i - 2] && trial[i] < 0.0) trial[i] = 0.0;
            if (limits[0] < trial[0] && trial[0] < limits[1] && limits[2] < trial[1] && trial[1] < limits[3]) {
                expected(b, trial, trial_mean, trial_grad);
                double trial_nll = neg_log_likelihood(trial_mean, b->P, m, inv);
                if (trial_nll <= nll) {
                    memcpy(theta, trial, p * sizeof(double));
                    memcpy(mean, trial_mean, m * sizeof(double));
                    memcpy(grad, trial_grad, m * p * sizeof(double));
                    nll = trial_nll;
                    accepted = 1;
                    break;
                }
            }
            for (int i = 0; i < p; i++) step[i] /= 2;
        }
        if (!accepted) return 1; /* no decrease along the scoring direction: at the optimum within rounding */
    }
    return 0;
}

/* fisher_scoring(theta (2 + q), phase (m), n_samples, dt, fixed (m × (q − 2)), periodogram (m), nonnegative (q uint8),
 *                limits (4: f low, f high, σ low, σ high), max_iterations)
 *   -> (bytes of θ, converged (bool), bytes of the mean (m), bytes of the gradient (m × (2 + q))) */
static PyObject *py_fisher_scoring(PyObject *self, PyObject *args) {
    PyObject *objs[6];
    Py_ssize_t n_samples;
    double dt;
    int max_iterations;
    if (!PyArg_ParseTuple(args, "OOndOOOOi", &objs[0], &objs[1], &n_samples, &dt, &objs[2], &objs[3], &objs[4],
                          &objs[5], &max_iterations))
        return NULL;
    Py_buffer views[6];
    PyObject *result = NULL;
    int got = open_views(objs, 6, views);
    if (got < 6) goto done;
    Py_ssize_t m = views[1].len / (Py_ssize_t)sizeof(double);
    int q = (int)views[4].len, p = q + 2;
    if (q < 2 || q > MAX_COLUMNS || m < 1 || views[0].len != p * (Py_ssize_t)sizeof(double)
        || views[3].len != m * (Py_ssize_t)sizeof(double) || views[2].len != m * (q - 2) * (Py_ssize_t)sizeof(double)
        || views[5].len != 4 * (Py_ssize_t)sizeof(double)) {
        PyErr_SetString(PyExc_ValueError, "fisher_scoring: theta, phase, fixed, periodogram and limits must agree");
        goto done;
    }
    Band b = {views[1].buf, views[2].buf, views[3].buf, views[4].buf, m, q, (double)n_samples, dt};
    PyObject *theta = PyBytes_FromStringAndSize(views[0].buf, p * (Py_ssize_t)sizeof(double));
    PyObject *mean = PyBytes_FromStringAndSize(NULL, m * (Py_ssize_t)sizeof(double));
    PyObject *grad = PyBytes_FromStringAndSize(NULL, m * p * (Py_ssize_t)sizeof(double));
    double *work = malloc((2 * m + m * p) * sizeof(double));
    if (!theta || !mean || !grad || !work) {
        Py_XDECREF(theta); Py_XDECREF(mean); Py_XDECREF(grad); free(work);
        PyErr_NoMemory();
        goto done;
    }
    int ok;
    Py_BEGIN_ALLOW_THREADS
    ok = scoring(&b, (double *)PyBytes_AS_STRING(theta), views[5].buf, max_iterations,
                 (double *)PyBytes_AS_STRING(mean), (double *)PyBytes_AS_STRING(grad), work);
    Py_END_ALLOW_THREADS
    free(work);
    result = Py_BuildValue("NONN", theta, ok ? Py_True : Py_False, mean, grad);
done:
    close_views(views, got);
    return result;
}

/* linear_many(bases (c × m × q float64), periodogram (m float64), nonnegative (q uint8), iterations)
 *   -> (bytes of float64 coefficients, c × q; bytes of float64 -log-likelihoods, c) */
static PyObject *py_linear_many(PyObject *self, PyObject *args) {
    PyObject *objs[3];
    int iterations;
    if (!PyArg_ParseTuple(args, "OOOi", &objs[0], &objs[1], &objs[2], &iterations)) return NULL;
    Py_buffer views[3];
    PyObject *result = NULL;
    int got = open_views(objs, 3, views);
    if (got < 3) goto done;
    Py_ssize_t m = views[1].len / (Py_ssize_t)sizeof(double);
    int q = (int)views[2].len;
    if (q < 2 || q > MAX_COLUMNS || m < 1 || views[0].len % (m * q * (Py_ssize_t)sizeof(double)) != 0) {
        PyErr_SetString(PyExc_ValueError, "linear_many: bases must be candidates x bins x 2..32 columns");
        goto done;
    }
    Py_ssize_t c = views[0].len / (m * q * (Py_ssize_t)sizeof(double));
    const double *B = views[0].buf, *P = views[1].buf;
    const unsigned char *nonneg = views[2].buf;
    PyObject *lin = PyBytes_FromStringAndSize(NULL, c * q * (Py_ssize_t)sizeof(double));
    PyObject *nll = PyBytes_FromStringAndSize(NULL, c * (Py_ssize_t)sizeof(double));
    double *work = malloc(4 * m * sizeof(double));
    if (!lin || !nll || !work) {
        Py_XDECREF(lin); Py_XDECREF(nll); free(work);
        PyErr_NoMemory();
        goto done;
    }
    double *L = (double *)PyBytes_AS_STRING(lin), *N = (double *)PyBytes_AS_STRING(nll);
    Py_BEGIN_ALLOW_THREADS
    double level = 0.0;
    for (Py_ssize_t k = 0; k < m; k++) level += P[k];
    level /= (double)m;
    for (Py_ssize_t i = 0; i < c; i++)
        N[i] = fit_candidate(B + i * m * q, P, nonneg, m, q, iterations, level, L + i * q, work);
    Py_END_ALLOW_THREADS
    free(work);
    result = Py_BuildValue("NN", lin, nll);
done:
    close_views(views, got);
    return result;
}

static PyMethodDef methods[] = {
    {"linear_many", py_linear_many, METH_VARARGS,
     "Whittle fits of the linear terms of many candidate bases: coefficients and -log-likelihoods."},
    {"fisher_scoring", py_fisher_scoring, METH_VARARGS,
     "Fisher scoring of one pole and its linear terms in a band: theta, converged, mean, gradient."},
    {"grid", py_grid, METH_VARARGS,
     "Whittle fits of the linear terms of a mode's pole at many (f, decay rate) beside fixed columns."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_whittle_kernel", NULL, -1, methods};

PyMODINIT_FUNC PyInit__whittle_kernel(void) { return PyModule_Create(&module); }
