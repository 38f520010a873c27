/* The forward and backward passes of minvar.lqg's solver, compiled: the
 * extension module minvar._lqg_kernel, called by minvar/_kernel.py.
 *
 * Each function here is the compiled twin of a Python function that it must
 * match to rounding (tests/test_speed_solver.py compares the two engines):
 *   lqg_forward     minvar.lqg._Solver.forward (its moments: minvar.moments.Moments.step
 *                   with the optimal filter's shortcut)
 *   lqg_backward    minvar.lqg._Solver.backward
 *   lqg_error_cov   minvar.moments.Moments.step under any gains (the Mee it returns)
 *   lqg_mean_states minvar.moments.mean_states
 * The passes are those of Todorov's kalman_lqg.m, for the case every planning
 * problem of this project is in: the filter and controller systems are
 * positive definite (Cholesky), so no pseudo-inverse is needed. The products
 * exploit the structure of the problems (A, B and H are mostly zeros: a plant
 * of a few chained integrators, constant states, observations of a few states)
 * by keeping those matrices in compressed-row form; every other product is
 * dense. The arithmetic is that of the numpy code up to the order of
 * summation, so the results agree to rounding.
 *
 * Matrices are row-major doubles. The recursions return 0, or a positive code
 * when a Cholesky factorisation fails (the caller then uses numpy) or a
 * negative one when memory runs out. The module functions at the end check
 * every buffer against the problem's sizes and run the recursions without the
 * GIL.
 */

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

enum {
    HAS_C = 1,         /* control-dependent noise */
    HAS_D = 2,         /* state-dependent observation noise */
    TRACK_XE = 4,      /* internal noise: the estimate/error cross moment */
    ADD_NOISE = 8,     /* additive process or internal noise in the error moment */
    NOISE_COST = 16,   /* additive noise terms of the cost */
};

/* A matrix in compressed-row form. */
typedef struct {
    int rows, cols;
    int *start;   /* rows + 1 */
    int *col;
    double *val;
} csr;

static int csr_make(csr *s, const double *X, int rows, int cols) {
    int nnz = 0;
    for (int i = 0; i < rows * cols; i++) nnz += X[i] != 0.0;
    s->rows = rows;
    s->cols = cols;
    s->start = malloc(sizeof(int) * (rows + 1));
    s->col = malloc(sizeof(int) * (nnz ? nnz : 1));
    s->val = malloc(sizeof(double) * (nnz ? nnz : 1));
    if (!s->start || !s->col || !s->val) return -1;
    int p = 0;
    for (int i = 0; i < rows; i++) {
        s->start[i] = p;
        for (int j = 0; j < cols; j++) {
            double v = X[i * cols + j];
            if (v != 0.0) {
                s->col[p] = j;
                s->val[p] = v;
                p++;
            }
        }
    }
    s->start[rows] = p;
    return 0;
}

static void csr_free(csr *s) {
    free(s->start);
    free(s->col);
    free(s->val);
}

static void transpose(double *out, const double *X, int rows, int cols) {
    for (int i = 0; i < rows; i++)
        for (int j = 0; j < cols; j++) out[j * rows + i] = X[i * cols + j];
}

/* out (S.rows x r) = S X, X (S.cols x r); sign -1 subtracts from out instead. */
static void sd(double *out, const csr *S, const double *X, int r, int accumulate) {
    for (int i = 0; i < S->rows; i++) {
        double *o = out + (size_t)i * r;
        if (!accumulate) memset(o, 0, sizeof(double) * r);
        for (int p = S->start[i]; p < S->start[i + 1]; p++) {
            const double v = accumulate < 0 ? -S->val[p] : S->val[p];
            const double *x = X + (size_t)S->col[p] * r;
            for (int j = 0; j < r; j++) o[j] += v * x[j];
        }
    }
}

/* out (p x S.cols) = X S, X (p x S.rows): a pass over X's columns per non-zero of S. */
static void ds(double *out, const double *X, const csr *S, int p, int accumulate) {
    const int q = S->rows, r = S->cols;
    if (!accumulate) memset(out, 0, sizeof(double) * (size_t)p * r);
    for (int l = 0; l < q; l++) {
        for (int t = S->start[l]; t < S->start[l + 1]; t++) {
            const int j = S->col[t];
            const double v = accumulate < 0 ? -S->val[t] : S->val[t];
            for (int i = 0; i < p; i++) out[(size_t)i * r + j] += v * X[(size_t)i * q + l];
        }
    }
}

/* out (p x r) = X Y, X (p x q), Y (q x r); accumulate -1 subtracts. */
static void dd(double *out, const double *X, const double *Y, int p, int q, int r,
               int accumulate) {
    for (int i = 0; i < p; i++) {
        double *o = out + (size_t)i * r;
        if (!accumulate) memset(o, 0, sizeof(double) * r);
        const double *x = X + (size_t)i * q;
        for (int l = 0; l < q; l++) {
            double xv = x[l];
            if (xv == 0.0) continue;
            if (accumulate < 0) xv = -xv;
            const double *y = Y + (size_t)l * r;
            for (int j = 0; j < r; j++) o[j] += xv * y[j];
        }
    }
}

/* out (p x r) = X Y', X (p x q), Y (r x q). */
static void ddt(double *out, const double *X, const double *Y, int p, int q, int r,
                int accumulate) {
    for (int i = 0; i < p; i++) {
        const double *x = X + (size_t)i * q;
        int zero = 1;
        for (int l = 0; l < q && zero; l++) zero = x[l] == 0.0;
        if (zero) { /* rows of zeros are common (gains of constant states) */
            if (!accumulate) memset(out + (size_t)i * r, 0, sizeof(double) * r);
            continue;
        }
        for (int j = 0; j < r; j++) {
            const double *y = Y + (size_t)j * q;
            double s = 0.0;
            for (int l = 0; l < q; l++) s += x[l] * y[l];
            double *o = out + (size_t)i * r + j;
            if (accumulate < 0) *o -= s;
            else if (accumulate) *o += s;
            else *o = s;
        }
    }
}

/* out (p x r) = X' Y, X (q x p), Y (q x r). */
static void dtd(double *out, const double *X, const double *Y, int p, int q, int r,
                int accumulate) {
    if (!accumulate) memset(out, 0, sizeof(double) * (size_t)p * r);
    for (int l = 0; l < q; l++) {
        const double *x = X + (size_t)l * p;
        const double *y = Y + (size_t)l * r;
        for (int i = 0; i < p; i++) {
            double xv = x[i];
            if (xv == 0.0) continue;
            if (accumulate < 0) xv = -xv;
            double *o = out + (size_t)i * r;
            for (int j = 0; j < r; j++) o[j] += xv * y[j];
        }
    }
}

/* Solve M X = Y for symmetric positive definite M (d x d, its upper triangle
 * read, as LAPACK's dposv with uplo 'U'), Y (d x r) overwritten by X.
 * U is d x d scratch. Returns 0, or 1 if M is not positive definite. */
static int chol_solve(const double *M, double *Y, double *U, int d, int r) {
    /* M = U' U, U upper triangular */
    for (int j = 0; j < d; j++) {
        double s = M[j * d + j];
        for (int l = 0; l < j; l++) s -= U[l * d + j] * U[l * d + j];
        if (!(s > 0.0)) return 1;
        const double ujj = sqrt(s);
        U[j * d + j] = ujj;
        for (int i = j + 1; i < d; i++) {
            double t = M[j * d + i];
            for (int l = 0; l < j; l++) t -= U[l * d + j] * U[l * d + i];
            U[j * d + i] = t / ujj;
        }
    }
    /* all right-hand sides at once, a row at a time (contiguous) */
    for (int i = 0; i < d; i++) { /* U' z = y */
        double *yi = Y + (size_t)i * r;
        for (int l = 0; l < i; l++) {
            const double u = U[l * d + i];
            const double *yl = Y + (size_t)l * r;
            for (int c = 0; c < r; c++) yi[c] -= u * yl[c];
        }
        const double uii = U[i * d + i];
        for (int c = 0; c < r; c++) yi[c] /= uii;
    }
    for (int i = d - 1; i >= 0; i--) { /* U x = z */
        double *yi = Y + (size_t)i * r;
        for (int l = i + 1; l < d; l++) {
            const double u = U[i * d + l];
            const double *yl = Y + (size_t)l * r;
            for (int c = 0; c < r; c++) yi[c] -= u * yl[c];
        }
        const double uii = U[i * d + i];
        for (int c = 0; c < r; c++) yi[c] /= uii;
    }
    return 0;
}

/* Doubles in one scratch block: room for any product of the problem's sizes. */
static size_t block_size(int n, int m, int k) {
    int big = n > m ? n : m;
    big = big > k ? big : k;
    return (size_t)big * big + 8;
}

static void add(double *out, const double *X, int size) {
    for (int i = 0; i < size; i++) out[i] += X[i];
}

/* What every recursion sets up first: A, B, H and their transposes in
 * compressed-row form, and its scratch, `count` blocks of block_size doubles
 * (after three that hold the dense transposes). */
typedef struct {
    csr A, At, B, Bt, H, Ht;
    size_t blk;
    double *buf;   /* the dense transposes, then the caller's blocks */
    double *work;  /* the caller's first block */
} sparse_t;

static void sparse_close(sparse_t *s) {
    csr_free(&s->A);
    csr_free(&s->At);
    csr_free(&s->B);
    csr_free(&s->Bt);
    csr_free(&s->H);
    csr_free(&s->Ht);
    free(s->buf);
}

/* 0, or -1 when memory runs out (sparse_close still frees what was made). */
static int sparse_open(sparse_t *s, const double *A, const double *B, const double *H, int n,
                       int m, int k, int count) {
    memset(s, 0, sizeof *s);
    s->blk = block_size(n, m, k);
    s->buf = malloc(sizeof(double) * s->blk * (3 + (size_t)count));
    if (!s->buf) return -1;
    double *At = s->buf, *Bt = At + s->blk, *Ht = Bt + s->blk;
    s->work = Ht + s->blk;
    transpose(At, A, n, n);
    transpose(Bt, B, n, m);
    transpose(Ht, H, k, n);
    if (csr_make(&s->A, A, n, n) || csr_make(&s->At, At, n, n) || csr_make(&s->B, B, n, m)
        || csr_make(&s->Bt, Bt, m, n) || csr_make(&s->H, H, k, n) || csr_make(&s->Ht, Ht, n, k))
        return -1;
    return 0;
}

/* Filter gains K (T x n x k) optimal for control gains L (T x m x n), with the
 * moments SiX, SiXE, SiE (Mhh, Mhe, Mee of minvar.moments.Moments) stepped
 * with the optimal filter's shortcut. BC: nc matrices B C_i (n x m); D: nd
 * matrices (k x n). */
static int lqg_forward(int T, int n, int m, int k, int nc, int nd, const double *A,
                       const double *B, const double *H, const double *BC, const double *D,
                       const double *DD0, const double *CC0, const double *EE0,
                       const double *S1, const double *X1, const double *L, int flags,
                       double *K) {
    const size_t nn = (size_t)n * n, nk = (size_t)n * k;
    sparse_t pl;
    if (sparse_open(&pl, A, B, H, n, m, k, 22)) {
        sparse_close(&pl);
        return -1;
    }
    const size_t blk = pl.blk;
    int status = -1;
    double *SiE = pl.work, *SiX = SiE + blk, *SiXE = SiX + blk;
    double *newE = SiXE + blk, *T1 = newE + blk, *T2 = T1 + blk, *T3 = T2 + blk;
    double *abl = T3 + blk, *akh = abl + blk, *X2 = akh + blk, *tmpS = X2 + blk;
    double *cross = tmpS + blk, *SiEHt = cross + blk, *ASH = SiEHt + blk, *Kt = ASH + blk;
    double *M = Kt + blk, *U = M + blk, *LS = U + blk, *LSL = LS + blk, *HS = LSL + blk;
    double *BCL = HS + blk;
    memcpy(SiE, S1, sizeof(double) * nn);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) SiX[i * n + j] = X1[i] * X1[j];
    memset(SiXE, 0, sizeof(double) * nn);
    for (int t = 0; t < T; t++) {
        const double *Lt = L + (size_t)t * m * n;
        double *Kout = K + (size_t)t * nk;
        ds(SiEHt, SiE, &pl.Ht, n, 0);                   /* SiE H' */
        sd(M, &pl.H, SiEHt, k, 0);                      /* H SiE H' */
        add(M, DD0, k * k);
        if (flags & HAS_D) {
            for (size_t i = 0; i < nn; i++)
                tmpS[i] = SiE[i] + SiX[i] + SiXE[i] + SiXE[(i % n) * n + i / n];
            for (int d = 0; d < nd; d++) {
                const double *Dd = D + (size_t)d * k * n;
                dd(X2, Dd, tmpS, k, n, n, 0);          /* D temp */
                ddt(M, X2, Dd, k, n, k, 1);            /* D temp D' */
            }
        }
        sd(ASH, &pl.A, SiEHt, k, 0);                    /* A SiE H' */
        transpose(Kt, ASH, n, k);                     /* (k x n) */
        if (chol_solve(M, Kt, U, k, n)) {
            status = 1;
            goto done;
        }
        transpose(Kout, Kt, k, n);                    /* K = A SiE H' M^-1 */
        /* akh = A - K H */
        memcpy(akh, A, sizeof(double) * nn);
        ds(akh, Kout, &pl.H, n, -1);
        /* newE = akh SiE A' = (A SiE - K (H SiE)) A' */
        sd(T1, &pl.A, SiE, n, 0);
        sd(HS, &pl.H, SiE, n, 0);                       /* (k x n) */
        dd(T1, Kout, HS, n, k, n, -1);
        ds(newE, T1, &pl.At, n, 0);
        if (flags & HAS_C) {
            dd(LS, Lt, SiX, m, n, n, 0);
            ddt(LSL, LS, Lt, m, n, m, 0);             /* L SiX L' */
            for (int c = 0; c < nc; c++) {
                const double *BCc = BC + (size_t)c * n * m;
                dd(BCL, BCc, LSL, n, m, m, 0);
                ddt(newE, BCL, BCc, n, m, n, 1);      /* + BC_i (L SiX L') BC_i' */
            }
        }
        if (flags & ADD_NOISE) {
            add(newE, EE0, (int)nn);
            add(newE, CC0, (int)nn);
        }
        /* abl = A - B L */
        memcpy(abl, A, sizeof(double) * nn);
        sd(abl, &pl.B, Lt, n, -1);
        double *SiXnew = T2;
        ddt(SiXnew, Kout, ASH, n, k, n, 0);           /* K (A SiE H')' */
        /* abl SiX abl' = (A SiX - B (L SiX)) (A - B L)' */
        if (!(flags & HAS_C)) dd(LS, Lt, SiX, m, n, n, 0);
        sd(T1, &pl.A, SiX, n, 0);
        sd(T1, &pl.B, LS, n, -1);                       /* Y = abl SiX */
        ds(SiXnew, T1, &pl.At, n, 1);                   /* + Y A' */
        ddt(T3, T1, Lt, n, n, m, 0);                  /* Y L' (n x m) */
        {
            /* - (Y L') B' */
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++) {
                    double s = 0.0;
                    for (int p = pl.B.start[j]; p < pl.B.start[j + 1]; p++)
                        s += T3[i * m + pl.B.col[p]] * pl.B.val[p];
                    SiXnew[i * n + j] -= s;
                }
        }
        if (flags & TRACK_XE) {
            /* cross = abl SiXE H' K' */
            dd(T1, abl, SiXE, n, n, n, 0);
            ds(X2, T1, &pl.Ht, n, 0);                   /* (n x k) */
            ddt(cross, X2, Kout, n, k, n, 0);
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++)
                    SiXnew[i * n + j] += EE0[i * n + j] + cross[i * n + j] + cross[j * n + i];
            /* SiXE = abl SiXE akh' - EE0 */
            ddt(T3, T1, akh, n, n, n, 0);
            for (size_t i = 0; i < nn; i++) SiXE[i] = T3[i] - EE0[i];
        }
        memcpy(SiX, SiXnew, sizeof(double) * nn);
        /* akh SiE A' is symmetric only in exact arithmetic: with little sensory noise its
         * rounding grows from step to step until the iteration diverges (as moments.py) */
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++)
                SiE[i * n + j] = 0.5 * (newE[i * n + j] + newE[j * n + i]);
    }
    status = 0;
done:
    sparse_close(&pl);
    return status;
}

/* Control gains L (T x m x n) optimal for filter gains K (T x n x k), and the
 * expected cost. C: nc matrices (m x m); D: nd matrices (k x n); Q (T+1 x n x n). */
static int lqg_backward(int T, int n, int m, int k, int nc, int nd, const double *A,
                        const double *B, const double *H, const double *C, const double *D,
                        const double *DD0, const double *CC0, const double *EE0,
                        const double *Q, const double *R, const double *X1, const double *S1,
                        const double *K, int flags, double *L, double *cost_out) {
    const size_t nn = (size_t)n * n, nm = (size_t)n * m;
    sparse_t pl;
    if (sparse_open(&pl, A, B, H, n, m, k, 23)) {
        sparse_close(&pl);
        return -1;
    }
    const size_t blk = pl.blk;
    int status = -1;
    char *Qzero = NULL;
    double *Sx = pl.work, *Se = Sx + blk;
    double *SxNew = Se + blk, *SeNew = SxNew + blk, *AtSx = SeNew + blk, *T1 = AtSx + blk;
    double *T2 = T1 + blk, *ASBL = T2 + blk, *SxB = ASBL + blk, *AtSxB = SxB + blk;
    double *Lt = AtSxB + blk, *SeB = Lt + blk, *SeK = SeB + blk, *KZ = SeK + blk;
    double *BSxB = KZ + blk, *temp = BSxB + blk, *BSeB = temp + blk, *Ctmp = BSeB + blk;
    double *U = Ctmp + blk, *KSeK = U + blk, *Kbuf = KSeK + blk;
    double cost = 0.0;
    Qzero = malloc((size_t)T + 1);
    if (!Qzero) goto done;
    for (int t = 0; t <= T; t++) {
        const double *Qt = Q + (size_t)t * nn;
        Qzero[t] = 1;
        for (size_t i = 0; i < nn && Qzero[t]; i++) Qzero[t] = Qt[i] == 0.0;
    }
    memcpy(Sx, Q + (size_t)T * nn, sizeof(double) * nn);
    memset(Se, 0, sizeof(double) * nn);
    for (int t = T - 1; t >= 0; t--) {
        const double *Kt = K + (size_t)t * n * k;
        dtd(SeK, Kt, Se, k, n, n, 0);                  /* K' Se (k x n) */
        if (flags & NOISE_COST) {
            /* tr(Sx CC0) + tr(Se (K DD0 K' + EE0 + CC0)), tr(Se K DD0 K') = sum (DD0 K'Se) .* K' */
            double s = 0.0;
            if (flags & ADD_NOISE)
                for (int i = 0; i < n; i++)
                    for (int j = 0; j < n; j++)
                        s += Sx[i * n + j] * CC0[j * n + i]
                             + Se[i * n + j] * (EE0[j * n + i] + CC0[j * n + i]);
            cost += s;
            dd(Kbuf, DD0, SeK, k, k, n, 0);             /* DD0 K' Se (k x n) */
            s = 0.0;
            for (int a = 0; a < k; a++)
                for (int i = 0; i < n; i++) s += Kbuf[a * n + i] * Kt[i * k + a];
            cost += s;
        }
        ds(SxB, Sx, &pl.B, n, 0);                        /* Sx B */
        sd(BSxB, &pl.Bt, SxB, m, 0);                     /* B' Sx B */
        for (int i = 0; i < m * m; i++) temp[i] = R[i] + BSxB[i];
        if (flags & HAS_C) {
            ds(SeB, Se, &pl.B, n, 0);
            sd(BSeB, &pl.Bt, SeB, m, 0);                 /* B' Se B */
            for (int i = 0; i < m * m; i++) BSeB[i] += BSxB[i];
            for (int c = 0; c < nc; c++) {
                const double *Cc = C + (size_t)c * m * m;
                dtd(Ctmp, Cc, BSeB, m, m, m, 0);       /* C' (B'(Sx+Se)B) */
                dd(temp, Ctmp, Cc, m, m, m, 1);        /* ... C */
            }
        }
        sd(AtSx, &pl.At, Sx, n, 0);                      /* A' Sx */
        ds(AtSxB, AtSx, &pl.B, n, 0);                    /* A' Sx B (n x m) */
        transpose(Lt, AtSxB, n, m);                    /* (m x n) */
        if (chol_solve(temp, Lt, U, m, n)) {
            status = 1;
            goto done;
        }
        memcpy(L + (size_t)t * nm, Lt, sizeof(double) * nm);
        dd(ASBL, AtSxB, Lt, n, m, n, 0);               /* A' Sx B L */
        /* Se' = ASBL + akh' Se akh, akh = A - K H:
         * Z = Se akh = Se A - (Se K) H;  akh' Z = A' Z - H' (K' Z) */
        ds(T1, Se, &pl.A, n, 0);
        for (int a = 0; a < k; a++)                    /* Z = Se A - (Se K) H */
            for (int p = pl.H.start[a]; p < pl.H.start[a + 1]; p++) {
                const int j = pl.H.col[p];
                const double v = pl.H.val[p];
                const double *z = SeK + (size_t)a * n;
                for (int i = 0; i < n; i++) T1[(size_t)i * n + j] -= v * z[i];
            }
        sd(SeNew, &pl.At, T1, n, 0);
        dtd(KZ, Kt, T1, k, n, n, 0);                   /* K' Z (k x n) */
        sd(SeNew, &pl.Ht, KZ, n, -1);
        add(SeNew, ASBL, (int)nn);
        /* Sx' = Q[t] + A' Sx A - ASBL */
        ds(SxNew, AtSx, &pl.A, n, 0);
        const double *Qt = Q + (size_t)t * nn;
        if (Qzero[t])  /* most steps cost nothing: leave Q[t] unread */
            for (size_t i = 0; i < nn; i++) SxNew[i] -= ASBL[i];
        else
            for (size_t i = 0; i < nn; i++) SxNew[i] += Qt[i] - ASBL[i];
        if (flags & HAS_D) {
            dtd(T2, Kt, Se, k, n, n, 0);               /* K' Se (k x n) */
            dd(KSeK, T2, Kt, k, n, k, 0);              /* K' Se K */
            for (int d = 0; d < nd; d++) {
                const double *Dd = D + (size_t)d * k * n;
                dtd(T2, Dd, KSeK, n, k, k, 0);         /* D' KSeK (n x k) */
                dd(SxNew, T2, Dd, n, k, n, 1);
            }
        }
        memcpy(Sx, SxNew, sizeof(double) * nn);
        memcpy(Se, SeNew, sizeof(double) * nn);
    }
    {
        double s = 0.0;
        for (int i = 0; i < n; i++) {
            double r = 0.0;
            for (int j = 0; j < n; j++) r += Sx[i * n + j] * X1[j];
            s += X1[i] * r;
        }
        double tr = 0.0;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) tr += (Se[i * n + j] + Sx[i * n + j]) * S1[j * n + i];
        cost += s + tr;
    }
    *cost_out = cost;
    status = 0;
done:
    free(Qzero);
    sparse_close(&pl);
    return status;
}

/* Exact second moments of the estimation error e = x - xhat under arbitrary
 * gains K, L (the covariance minvar.lqg.estimation_error_covariance returns):
 * the recursion of minvar.moments.Moments.step, in the same (xhat, e)
 * coordinates: E[e] = 0, and with Y = A - B L,
 * Z = K H, akh = A - K H, W = K (sum_j D_j Mxx D_j' + D0 D0') K' + E0 E0':
 *   Mhh' = Y Mhh Y' + Y Mhe Z' + Z Meh Y' + Z Mee Z' + W
 *   Mhe' = (Y Mhe + Z Mee) akh' - W
 *   Mee' = akh Mee akh' + sum_i B C_i L Mhh L' C_i' B' + W + C0 C0'
 * with Mxx = Mhh + Mhe + Meh + Mee. P receives Mee for t = 0..T. */
static int lqg_error_cov(int T, int n, int m, int k, int nc, int nd, const double *A,
                         const double *B, const double *H, const double *BC, const double *D,
                         const double *DD0, const double *CC0, const double *EE0,
                         const double *S1, const double *X1, const double *K, const double *L,
                         double *P) {
    const size_t nn = (size_t)n * n;
    sparse_t pl;
    if (sparse_open(&pl, A, B, H, n, m, k, 18)) {
        sparse_close(&pl);
        return -1;
    }
    const size_t blk = pl.blk;
    int status = -1;
    double *Mhh = pl.work, *Mhe = Mhh + blk, *Mee = Mhe + blk;
    double *U1 = Mee + blk, *U2 = U1 + blk, *V = U2 + blk, *VH = V + blk, *W = VH + blk;
    double *Nhh = W + blk, *Nhe = Nhh + blk, *Nee = Nhe + blk, *LP = Nee + blk;
    double *LPL = LP + blk, *BCL = LPL + blk, *HE = BCL + blk, *VL = HE + blk;
    double *Mxx = VL + blk, *X2 = Mxx + blk;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) Mhh[i * n + j] = X1[i] * X1[j];
    memset(Mhe, 0, sizeof(double) * nn);
    memcpy(Mee, S1, sizeof(double) * nn);
    memcpy(P, Mee, sizeof(double) * nn);
    for (int t = 0; t < T; t++) {
        const double *Kt = K + (size_t)t * n * k, *Lt = L + (size_t)t * m * n;
        /* W = K (Dsum + DD0) K' + EE0 */
        memcpy(X2, DD0, sizeof(double) * k * k);
        if (nd) {
            for (int i = 0; i < n; i++)
                for (int j = 0; j < n; j++)
                    Mxx[i * n + j] = Mhh[i * n + j] + Mhe[i * n + j] + Mhe[j * n + i]
                                     + Mee[i * n + j];
            for (int d = 0; d < nd; d++) {
                const double *Dd = D + (size_t)d * k * n;
                dd(V, Dd, Mxx, k, n, n, 0);
                ddt(X2, V, Dd, k, n, k, 1);
            }
        }
        dd(VH, Kt, X2, n, k, k, 0);
        ddt(W, VH, Kt, n, k, n, 0);
        add(W, EE0, (int)nn);
        /* U1 = Y Mhe = A Mhe - B (L Mhe);  U2 = Z Mee = K (H Mee) */
        sd(U1, &pl.A, Mhe, n, 0);
        dd(LP, Lt, Mhe, m, n, n, 0);
        sd(U1, &pl.B, LP, n, -1);
        sd(HE, &pl.H, Mee, n, 0);
        dd(U2, Kt, HE, n, k, n, 0);
        /* V = Y Mhh = A Mhh - B (L Mhh) */
        dd(LP, Lt, Mhh, m, n, n, 0);
        sd(V, &pl.A, Mhh, n, 0);
        sd(V, &pl.B, LP, n, -1);
        /* Nhh = V Y' = V A' - (V L') B' */
        ds(Nhh, V, &pl.At, n, 0);
        ddt(VL, V, Lt, n, n, m, 0);
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                double s = 0.0;
                for (int p = pl.B.start[j]; p < pl.B.start[j + 1]; p++)
                    s += VL[i * m + pl.B.col[p]] * pl.B.val[p];
                Nhh[i * n + j] -= s;
            }
        /* + U1 Z' + Z U1' + U2 Z', with V Z' = (V H') K' */
        ds(VH, U1, &pl.Ht, n, 0);
        ddt(X2, VH, Kt, n, k, n, 0);                  /* U1 Z' */
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) Nhh[i * n + j] += X2[i * n + j] + X2[j * n + i];
        ds(VH, U2, &pl.Ht, n, 0);
        ddt(Nhh, VH, Kt, n, k, n, 1);
        add(Nhh, W, (int)nn);
        /* Nhe = (U1 + U2) akh' - W, V akh' = V A' - (V H') K' */
        add(U1, U2, (int)nn);
        ds(Nhe, U1, &pl.At, n, 0);
        ds(VH, U1, &pl.Ht, n, 0);
        ddt(Nhe, VH, Kt, n, k, n, -1);
        for (size_t i = 0; i < nn; i++) Nhe[i] -= W[i];
        /* Nee = (A Mee - U2) akh' + noise + W + CC0 */
        sd(V, &pl.A, Mee, n, 0);
        for (size_t i = 0; i < nn; i++) V[i] -= U2[i];
        ds(Nee, V, &pl.At, n, 0);
        ds(VH, V, &pl.Ht, n, 0);
        ddt(Nee, VH, Kt, n, k, n, -1);
        if (nc) {
            dd(LP, Lt, Mhh, m, n, n, 0);
            ddt(LPL, LP, Lt, m, n, m, 0);             /* L Mhh L' */
            for (int c = 0; c < nc; c++) {
                const double *BCc = BC + (size_t)c * n * m;
                dd(BCL, BCc, LPL, n, m, m, 0);
                ddt(Nee, BCL, BCc, n, m, n, 1);
            }
        }
        for (size_t i = 0; i < nn; i++) Nee[i] += W[i] + CC0[i];
        memcpy(Mhh, Nhh, sizeof(double) * nn);
        memcpy(Mhe, Nhe, sizeof(double) * nn);
        memcpy(Mee, Nee, sizeof(double) * nn);
        memcpy(P + (size_t)(t + 1) * nn, Mee, sizeof(double) * nn);
    }
    status = 0;
    sparse_close(&pl);
    return status;
}

/* Noise-free mean states X (T+1 x n) under u = -L x from X1:
 * x' = A x - B (L x), numpy's (A - B L) x up to the order of summation.
 * Returns 0, or -1 when memory runs out. */
static int lqg_mean_states(int T, int n, int m, const double *A, const double *B,
                           const double *L, const double *X1, double *X) {
    double *u = malloc(sizeof(double) * (m ? m : 1));
    if (!u) return -1;
    memcpy(X, X1, sizeof(double) * n);
    for (int t = 0; t < T; t++) {
        const double *x = X + (size_t)t * n, *Lt = L + (size_t)t * m * n;
        double *y = X + (size_t)(t + 1) * n;
        for (int c = 0; c < m; c++) {
            double s = 0.0;
            for (int j = 0; j < n; j++) s += Lt[c * n + j] * x[j];
            u[c] = s;
        }
        for (int i = 0; i < n; i++) {
            double s = 0.0;
            for (int j = 0; j < n; j++) s += A[i * n + j] * x[j];
            for (int c = 0; c < m; c++) s -= B[i * m + c] * u[c];
            y[i] = s;
        }
    }
    free(u);
    return 0;
}

/* ---- The module: Python's buffers in, checked against the problem's sizes ---- */

/* Largest n, m, k, nc, nd: products of two fit an int, as the recursions index;
 * every buffer's size fits a Py_ssize_t (checked too). */
#define MAX_SIZE 10000
#define MAX_STEPS 100000000

typedef struct {
    int T, n, m, k, nc, nd;
} dims_t;

/* One buffer argument: its name, object, the doubles it must hold, and its view. */
typedef struct {
    const char *name;
    PyObject *obj;
    Py_ssize_t count;
    int writable;
    Py_buffer view;
} arg_t;

static int parse_dims(const char *func, PyObject *obj, dims_t *d) {
    if (!PyArg_ParseTuple(obj, "iiiiii;dims must be six ints (T, n, m, k, nc, nd)", &d->T,
                          &d->n, &d->m, &d->k, &d->nc, &d->nd))
        return -1;
    if (d->T < 0 || d->T > MAX_STEPS || d->n < 0 || d->n > MAX_SIZE || d->m < 0
        || d->m > MAX_SIZE || d->k < 0 || d->k > MAX_SIZE || d->nc < 0 || d->nc > MAX_SIZE
        || d->nd < 0 || d->nd > MAX_SIZE
        || (double)(d->T + 1) * (d->n + 1) * (d->n + d->m + d->k + d->nc + d->nd + 1)
               > (double)PY_SSIZE_T_MAX / sizeof(double)) {
        PyErr_Format(PyExc_ValueError,
                     "_lqg_kernel.%s: sizes (T, n, m, k, nc, nd) = (%d, %d, %d, %d, %d, %d) out "
                     "of range (0 to %d steps, 0 to %d otherwise)",
                     func, d->T, d->n, d->m, d->k, d->nc, d->nd, MAX_STEPS, MAX_SIZE);
        return -1;
    }
    return 0;
}

/* Whether a buffer's struct format is a native double. */
static int is_double(const char *format) {
    if (format == NULL) return 0; /* unsigned bytes */
#if PY_LITTLE_ENDIAN
    if (*format == '@' || *format == '=' || *format == '<') format++;
#else
    if (*format == '@' || *format == '=' || *format == '>' || *format == '!') format++;
#endif
    return format[0] == 'd' && format[1] == '\0';
}

static void release(arg_t *args, int count) {
    for (int i = 0; i < count; i++) PyBuffer_Release(&args[i].view);
}

/* Take the views of args[0..count): each C-contiguous float64 values, as many as
 * its count, writable where asked. 0, or -1 with a ValueError or TypeError
 * naming the function and argument, and no view held. */
static int take(const char *func, arg_t *args, int count) {
    for (int i = 0; i < count; i++) {
        arg_t *a = &args[i];
        const char *want = a->writable ? "writable C-contiguous float64" : "C-contiguous float64";
        if (!PyObject_CheckBuffer(a->obj)) {
            PyErr_Format(PyExc_TypeError, "_lqg_kernel.%s: %s: expected %zd %s values, got %.200s",
                         func, a->name, a->count, want, Py_TYPE(a->obj)->tp_name);
            release(args, i);
            return -1;
        }
        int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (a->writable ? PyBUF_WRITABLE : 0);
        if (PyObject_GetBuffer(a->obj, &a->view, flags) < 0) {
            PyErr_Clear(); /* numpy's reason (not contiguous, read-only) is in ours */
            PyErr_Format(PyExc_ValueError, "_lqg_kernel.%s: %s: expected %zd %s values",
                         func, a->name, a->count, want);
            release(args, i);
            return -1;
        }
        if (!is_double(a->view.format) || a->view.itemsize != (Py_ssize_t)sizeof(double)
            || a->view.len != a->count * (Py_ssize_t)sizeof(double)) {
            PyErr_Format(PyExc_ValueError,
                         "_lqg_kernel.%s: %s: expected %zd %s values, got %zd bytes of '%s'",
                         func, a->name, a->count, want, a->view.len,
                         a->view.format ? a->view.format : "B");
            release(args, i + 1);
            return -1;
        }
    }
    return 0;
}

#define BUF(i) ((double *)args[i].view.buf)

PyDoc_STRVAR(forward_doc,
"forward(dims, flags, A, B, H, BC, D, DD0, CC0, EE0, S1, X1, L, K) -> bool\n\n"
"Filter gains K (T, n, k), written in place, optimal for control gains L (T, m, n);\n"
"dims = (T, n, m, k, nc, nd), BC = B C_i (nc, n, m), D (nd, k, n). False when a\n"
"filter system is not positive definite (K is then incomplete).");

static PyObject *py_forward(PyObject *self, PyObject *py_args) {
    PyObject *dims, *o[12];
    dims_t d;
    int flags, status;
    (void)self;
    if (!PyArg_ParseTuple(py_args, "OiOOOOOOOOOOOO:forward", &dims, &flags, &o[0], &o[1],
                          &o[2], &o[3], &o[4], &o[5], &o[6], &o[7], &o[8], &o[9], &o[10], &o[11])
        || parse_dims("forward", dims, &d) < 0)
        return NULL;
    const Py_ssize_t T = d.T, n = d.n, m = d.m, k = d.k;
    arg_t args[] = {
        {"A", o[0], n * n, 0},         {"B", o[1], n * m, 0},
        {"H", o[2], k * n, 0},         {"BC", o[3], d.nc * n * m, 0},
        {"D", o[4], d.nd * k * n, 0},  {"DD0", o[5], k * k, 0},
        {"CC0", o[6], n * n, 0},       {"EE0", o[7], n * n, 0},
        {"S1", o[8], n * n, 0},        {"X1", o[9], n, 0},
        {"L", o[10], T * m * n, 0},    {"K", o[11], T * n * k, 1},
    };
    if (take("forward", args, 12) < 0) return NULL;
    Py_BEGIN_ALLOW_THREADS
    status = lqg_forward(d.T, d.n, d.m, d.k, d.nc, d.nd, BUF(0), BUF(1), BUF(2), BUF(3), BUF(4),
                         BUF(5), BUF(6), BUF(7), BUF(8), BUF(9), BUF(10), flags, BUF(11));
    Py_END_ALLOW_THREADS
    release(args, 12);
    if (status < 0) return PyErr_NoMemory();
    return PyBool_FromLong(status == 0);
}

PyDoc_STRVAR(backward_doc,
"backward(dims, flags, A, B, H, C, D, DD0, CC0, EE0, Q, R, X1, S1, K, L) -> float | None\n\n"
"Control gains L (T, m, n), written in place, optimal for filter gains K (T, n, k),\n"
"and their expected cost; C (nc, m, m), Q (T+1, n, n). None when a control system\n"
"is not positive definite (L is then incomplete).");

static PyObject *py_backward(PyObject *self, PyObject *py_args) {
    PyObject *dims, *o[14];
    dims_t d;
    int flags, status;
    double cost = 0.0;
    (void)self;
    if (!PyArg_ParseTuple(py_args, "OiOOOOOOOOOOOOOO:backward", &dims, &flags, &o[0], &o[1],
                          &o[2], &o[3], &o[4], &o[5], &o[6], &o[7], &o[8], &o[9], &o[10], &o[11],
                          &o[12], &o[13])
        || parse_dims("backward", dims, &d) < 0)
        return NULL;
    const Py_ssize_t T = d.T, n = d.n, m = d.m, k = d.k;
    arg_t args[] = {
        {"A", o[0], n * n, 0},          {"B", o[1], n * m, 0},
        {"H", o[2], k * n, 0},          {"C", o[3], d.nc * m * m, 0},
        {"D", o[4], d.nd * k * n, 0},   {"DD0", o[5], k * k, 0},
        {"CC0", o[6], n * n, 0},        {"EE0", o[7], n * n, 0},
        {"Q", o[8], (T + 1) * n * n, 0}, {"R", o[9], m * m, 0},
        {"X1", o[10], n, 0},            {"S1", o[11], n * n, 0},
        {"K", o[12], T * n * k, 0},     {"L", o[13], T * m * n, 1},
    };
    if (take("backward", args, 14) < 0) return NULL;
    Py_BEGIN_ALLOW_THREADS
    status = lqg_backward(d.T, d.n, d.m, d.k, d.nc, d.nd, BUF(0), BUF(1), BUF(2), BUF(3),
                          BUF(4), BUF(5), BUF(6), BUF(7), BUF(8), BUF(9), BUF(10), BUF(11),
                          BUF(12), flags, BUF(13), &cost);
    Py_END_ALLOW_THREADS
    release(args, 14);
    if (status < 0) return PyErr_NoMemory();
    if (status > 0) Py_RETURN_NONE;
    return PyFloat_FromDouble(cost);
}

PyDoc_STRVAR(error_cov_doc,
"error_cov(dims, A, B, H, BC, D, DD0, CC0, EE0, S1, X1, K, L, P) -> None\n\n"
"Cov[x - xhat] for t = 0..T under any gains K, L, written into P (T+1, n, n).");

static PyObject *py_error_cov(PyObject *self, PyObject *py_args) {
    PyObject *dims, *o[13];
    dims_t d;
    int status;
    (void)self;
    if (!PyArg_ParseTuple(py_args, "OOOOOOOOOOOOOO:error_cov", &dims, &o[0], &o[1], &o[2],
                          &o[3], &o[4], &o[5], &o[6], &o[7], &o[8], &o[9], &o[10], &o[11], &o[12])
        || parse_dims("error_cov", dims, &d) < 0)
        return NULL;
    const Py_ssize_t T = d.T, n = d.n, m = d.m, k = d.k;
    arg_t args[] = {
        {"A", o[0], n * n, 0},          {"B", o[1], n * m, 0},
        {"H", o[2], k * n, 0},          {"BC", o[3], d.nc * n * m, 0},
        {"D", o[4], d.nd * k * n, 0},   {"DD0", o[5], k * k, 0},
        {"CC0", o[6], n * n, 0},        {"EE0", o[7], n * n, 0},
        {"S1", o[8], n * n, 0},         {"X1", o[9], n, 0},
        {"K", o[10], T * n * k, 0},     {"L", o[11], T * m * n, 0},
        {"P", o[12], (T + 1) * n * n, 1},
    };
    if (take("error_cov", args, 13) < 0) return NULL;
    Py_BEGIN_ALLOW_THREADS
    status = lqg_error_cov(d.T, d.n, d.m, d.k, d.nc, d.nd, BUF(0), BUF(1), BUF(2), BUF(3),
                           BUF(4), BUF(5), BUF(6), BUF(7), BUF(8), BUF(9), BUF(10), BUF(11),
                           BUF(12));
    Py_END_ALLOW_THREADS
    release(args, 13);
    if (status < 0) return PyErr_NoMemory();
    Py_RETURN_NONE;
}

PyDoc_STRVAR(mean_states_doc,
"mean_states(dims, A, B, L, X1, X) -> None\n\n"
"Noise-free states x[t+1] = (A - B L[t]) x[t] from X1, written into X (T+1, n).");

static PyObject *py_mean_states(PyObject *self, PyObject *py_args) {
    PyObject *dims, *o[5];
    dims_t d;
    int status;
    (void)self;
    if (!PyArg_ParseTuple(py_args, "OOOOOO:mean_states", &dims, &o[0], &o[1], &o[2], &o[3],
                          &o[4])
        || parse_dims("mean_states", dims, &d) < 0)
        return NULL;
    const Py_ssize_t T = d.T, n = d.n, m = d.m;
    arg_t args[] = {
        {"A", o[0], n * n, 0}, {"B", o[1], n * m, 0}, {"L", o[2], T * m * n, 0},
        {"X1", o[3], n, 0},    {"X", o[4], (T + 1) * n, 1},
    };
    if (take("mean_states", args, 5) < 0) return NULL;
    Py_BEGIN_ALLOW_THREADS
    status = lqg_mean_states(d.T, d.n, d.m, BUF(0), BUF(1), BUF(2), BUF(3), BUF(4));
    Py_END_ALLOW_THREADS
    release(args, 5);
    if (status < 0) return PyErr_NoMemory();
    Py_RETURN_NONE;
}

static PyMethodDef kernel_methods[] = {
    {"forward", py_forward, METH_VARARGS, forward_doc},
    {"backward", py_backward, METH_VARARGS, backward_doc},
    {"error_cov", py_error_cov, METH_VARARGS, error_cov_doc},
    {"mean_states", py_mean_states, METH_VARARGS, mean_states_doc},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef kernel_module = {
    PyModuleDef_HEAD_INIT,
    "_lqg_kernel",
    "The compiled passes of minvar.lqg's solver (called by minvar._kernel).\n\n"
    "Matrices are C-contiguous float64 buffers (numpy arrays), checked against the\n"
    "problem's sizes dims = (T, n, m, k, nc, nd); outputs are written in place, and\n"
    "the recursions run without the GIL.",
    0,
    kernel_methods,
};

PyMODINIT_FUNC PyInit__lqg_kernel(void) { return PyModule_Create(&kernel_module); }
