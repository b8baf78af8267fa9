/* Ring kernels of the axisymmetric Laplace problem (Part I, section 1.4, eqs. (20)-(22); errata
 * items 1, 1a), compiled: the same formulas, in the same order of operations, as single_double and
 * single_double_split of semianalytic/bem/kernels.py (read their docstrings for the notation), the
 * dense blocks of assemble() (semianalytic/bem/solve.py: the surface against itself and against
 * its mirror image, once per pair) with the column weights applied, and the near and self rules of
 * PairQuadrature.integrate after the panel geometry (ring_pair_rules, the kernels of the same
 * block() as the others).  Built when the package is installed (setup.py, a setuptools Extension
 * loaded with ctypes by semianalytic/native.py); the numpy code of kernels.py and solve.py is the
 * reference and the fallback.
 *
 * K(1 - q), E(1 - q) from the Cephes approximations (S. L. Moshier; scipy.special.ellipkm1 /
 * ellipe), K = P_K(q) - ln(q) Q_K(q), E = P_E(q) - ln(q) q Q_E(q), by Horner's scheme (the
 * numpy code sums the same polynomials by powers: the two agree to a few units of 1e-16).
 * Compile without -ffast-math: IEEE arithmetic, inf/nan where numpy gives them (q = 0). */

#include <math.h>
#include <stddef.h>

#define PI 3.14159265358979323846

/* The kernels' loops without calls (block(), sym_tile()) are vectorised by the compiler.  On x86-64
 * Linux with GCC, WIDE builds each exported kernel twice, for AVX2 (four doubles a vector) and for the
 * baseline x86-64 (SSE2, two), and the loader picks the one the processor runs (an ifunc): a library
 * built on one machine still runs on an older one sharing the home folder.  AVX2 here brings no fused
 * multiply-add (that is the separate FMA extension, and -ffp-contract=off forbids it anyway): the same
 * IEEE operations in the same order on wider registers, so the same numbers, bit for bit (compiled with
 * -DRING_BASELINE, the baseline code only: tests/test_ring_kernel_c.py compares the two builds). */
#if !defined(RING_BASELINE) && defined(__x86_64__) && defined(__linux__) && defined(__GLIBC__) && defined(__GNUC__) \
    && !defined(__clang__) && __GNUC__ >= 8  /* glibc: the ifunc that picks a clone (musl has none) */
#define WIDE __attribute__((target_clones("avx2", "default")))
#else
#define WIDE
#endif
#define SPLIT_TERMS 10

/* The SHA-256 of this file, given by setup.py when it builds the library (-DRING_SOURCE_SHA256="..."):
 * semianalytic/native.py loads the library only when it matches the installed source. */
#ifndef RING_SOURCE_SHA256
#define RING_SOURCE_SHA256 ""
#endif
const char *ring_source_sha256(void) { return RING_SOURCE_SHA256; }

/* The polynomials, filled once by the loader from kernels.py (one home for the numbers):
 * the Cephes P_K, Q_K, P_E (11 coefficients) and Q_E (10), highest power first, and the
 * truncated series of K(q) and K(q) - E(q) in q (SPLIT_TERMS), lowest power first. */
static double PK[11], QK[11], PE[11], QE[10];
static double KSER[SPLIT_TERMS];
static double KMESER[SPLIT_TERMS];

void ring_set_coefficients(const double *pk, const double *qk, const double *pe, const double *qe,
                           const double *kser, const double *kmeser)
{
    for (int i = 0; i < 11; i++) {
        PK[i] = pk[i];
        QK[i] = qk[i];
        PE[i] = pe[i];
    }
    for (int i = 0; i < 10; i++)
        QE[i] = qe[i];
    for (int i = 0; i < SPLIT_TERMS; i++) {
        KSER[i] = kser[i];
        KMESER[i] = kmeser[i];
    }
}

static inline double horner(double q, const double *c, int n)
{
    double s = c[0];
    for (int i = 1; i < n; i++)
        s = s * q + c[i];
    return s;
}

static inline double series(double q, const double *c)
{
    double s = c[SPLIT_TERMS - 1];
    for (int i = SPLIT_TERMS - 2; i >= 0; i--)
        s = s * q + c[i];
    return s;
}

/* Points are taken in blocks of BLK: the logarithms (a library call) in one loop, everything
 * else in loops without calls that the compiler vectorises, so that the Horner chains of many
 * points overlap instead of waiting on each other.  The arithmetic of each point is the same. */
#define BLK 64

/* S, Dl (and, with QS != NULL, the coefficients QS, QD of L = -ln(1 - m)/2) of n <= BLK points:
 * differences dx = x - x1, dr = r - r1, sums s = r + r1, source radius r1 and normal (nx1, nr1);
 * with w != NULL, S and Dl are multiplied by w. */
/* K(m) and E(m) from q = 1 - m and ln q (Cephes' approximations: kernels.py's _PK, _QK, _PE, _QE). */
static inline void ellip_ke(double q, double lnq, double *K, double *E)
{
    *K = horner(q, PK, 11) - lnq * horner(q, QK, 11);
    *E = horner(q, PE, 11) - lnq * q * horner(q, QE, 10);
}

/* The single and double layer of one ring (Part I, eqs. (20)-(22); errata items 1, 1a) from K, E,
 * inv = 1/(pi sqrt D), d2 = dx^2 + dr^2, the differences dx, dr, the source radius r1 and normal
 * (nx1, nr1); the split form (block() with QS) groups bracket/d2 differently and stays there. */
static inline void ring_layers(double K, double E, double inv, double d2, double dx, double dr, double r1,
                               double nx1, double nr1, double *S, double *Dl)
{
    double bracket = r1 * (dx * nx1 + dr * nr1) + 0.5 * nr1 * d2;
    *S = r1 * K * inv;
    *Dl = (E * bracket / d2 - 0.5 * nr1 * K) * inv;
}

static inline __attribute__((always_inline)) void block(int n, const double *dx, const double *dr, const double *s, const double *r1,
                  const double *nx1, const double *nr1, const double *w,
                  double *restrict S, double *restrict Dl, double *restrict QS, double *restrict QD)
{
    double d2[BLK], D[BLK], q[BLK], lnq[BLK];
    const double two_over_pi = 2.0 / PI;
    for (int i = 0; i < n; i++) {
        d2[i] = dx[i] * dx[i] + dr[i] * dr[i];
        D[i] = dx[i] * dx[i] + s[i] * s[i];
        q[i] = d2[i] / D[i];
    }
    for (int i = 0; i < n; i++)
        lnq[i] = log(q[i]);
    if (QS == NULL) {
        for (int i = 0; i < n; i++) {
            double K, E;
            ellip_ke(q[i], lnq[i], &K, &E);
            ring_layers(K, E, 1.0 / (PI * sqrt(D[i])), d2[i], dx[i], dr[i], r1[i], nx1[i], nr1[i], S + i, Dl + i);
        }
        if (w)
            for (int i = 0; i < n; i++) {
                S[i] *= w[i];
                Dl[i] *= w[i];
            }
        return;
    }
    for (int i = 0; i < n; i++) {
        double K, E;
        ellip_ke(q[i], lnq[i], &K, &E);
        double Kc = series(q[i], KSER);
        double KcmEc = series(q[i], KMESER);
        double inv = 1.0 / (PI * sqrt(D[i]));
        double bracket_over_d2 = (r1[i] * (dx[i] * nx1[i] + dr[i] * nr1[i]) + 0.5 * nr1[i] * d2[i]) / d2[i];
        S[i] = r1[i] * K * inv;
        Dl[i] = (E * bracket_over_d2 - 0.5 * nr1[i] * K) * inv;
        QS[i] = r1[i] * two_over_pi * Kc * inv;
        QD[i] = two_over_pi * (KcmEc * bracket_over_d2 - 0.5 * nr1[i] * Kc) * inv;
    }
}

/* single_double (QS == NULL) or single_double_split on n points (every array contiguous, of
 * length n); ddx, ddr NULL or the `delta` differences. */
static inline __attribute__((always_inline)) void points(ptrdiff_t n, const double *x, const double *r, const double *x1, const double *r1,
                   const double *nx1, const double *nr1, const double *ddx, const double *ddr,
                   double *S, double *Dl, double *QS, double *QD)
{
    double dx[BLK], dr[BLK], s[BLK];
    for (ptrdiff_t a = 0; a < n; a += BLK) {
        int m = n - a < BLK ? (int)(n - a) : BLK;
        for (int i = 0; i < m; i++) {
            dx[i] = ddx ? ddx[a + i] : x[a + i] - x1[a + i];
            dr[i] = ddr ? ddr[a + i] : r[a + i] - r1[a + i];
            s[i] = r[a + i] + r1[a + i];
        }
        block(m, dx, dr, s, r1 + a, nx1 + a, nr1 + a, NULL, S + a, Dl + a,
              QS ? QS + a : NULL, QD ? QD + a : NULL);
    }
}

WIDE void ring_single_double(ptrdiff_t n, const double *x, const double *r, const double *x1,
                        const double *r1, const double *nx1, const double *nr1,
                        const double *ddx, const double *ddr, double *S, double *Dl)
{
    points(n, x, r, x1, r1, nx1, nr1, ddx, ddr, S, Dl, NULL, NULL);
}

WIDE void ring_single_double_split(ptrdiff_t n, const double *x, const double *r, const double *x1,
                              const double *r1, const double *nx1, const double *nr1,
                              const double *ddx, const double *ddr, double *S, double *Dl,
                              double *QS, double *QD)
{
    points(n, x, r, x1, r1, nx1, nr1, ddx, ddr, S, Dl, QS, QD);
}

/* The plain dense block: S[i, j], D[i, j] (row-major, nrow x ncol) of the targets (xr[i], rr[i]) against
 * the nodes (xc[j], rc[j]) with normals (nxc[j], nrc[j]), times the column weight wc[j] (the reference
 * of ring_dense_sym and ring_dense_mirror_sym, which assemble() calls). */
WIDE void ring_dense(ptrdiff_t nrow, const double *xr, const double *rr, ptrdiff_t ncol,
                const double *xc, const double *rc, const double *nxc, const double *nrc,
                const double *wc, double *S, double *D)
{
    double dx[BLK], dr[BLK], s[BLK];
    for (ptrdiff_t i = 0; i < nrow; i++) {
        double x = xr[i], r = rr[i];
        for (ptrdiff_t a = 0; a < ncol; a += BLK) {
            int m = ncol - a < BLK ? (int)(ncol - a) : BLK;
            for (int j = 0; j < m; j++) {
                dx[j] = x - xc[a + j];
                dr[j] = r - rc[a + j];
                s[j] = r + rc[a + j];
            }
            block(m, dx, dr, s, rc + a, nxc + a, nrc + a, wc + a, S + i * ncol + a, D + i * ncol + a,
                  NULL, NULL);
        }
    }
}

/* The block of ring_dense() whose targets are its own source nodes (the primary nodes against the primary
 * panels): the modulus of the elliptic integrals is symmetric in target and source (the differences only
 * change sign, the sum r + r1 commutes), so q, ln q, K, E and 1/(pi sqrt D) are computed once per pair
 * {i, j} and give both S[i, j] and S[j, i] (this project's own shortcut).  Each entry is the same
 * arithmetic, in the same order, as ring_dense's: the same numbers.  Nodes (x, r), normals (nx, nr),
 * weights w; rows of S and D ld apart; with skip != NULL the pairs with skip[i] and skip[j] both nonzero
 * are left as they are (their block is copied from a cache). */
#define TILE 32

/* One tile of ring_dense_sym (xs == NULL) or ring_dense_mirror_sym (xs != NULL): rows i0 .. i1-1 against
 * columns j0 .. j1-1 (j0 >= i0), the pairs with j >= i; the entries (i, j) written along the rows, then their
 * partner entries (j, i) along the rows too; pairs of two skipped nodes are computed (in a tile that also holds
 * others) but not written.  Without xs, source j is node j, dx = x_i - x_j (the partner's differences are
 * -dx, -dr).  With xs, source j is the image of node j in the free surface (x = xs[j], the same r and weight,
 * the normal (-nx_j, nr_j)), dx = x_i - xs[j], which the partner (j, i*) shares (x_j - xs[i] is the same
 * distance; dr changes sign).  Always inlined with a constant NULL or not: the compiler specialises each. */
static inline __attribute__((always_inline)) void
sym_tile(const double *xs, ptrdiff_t i0, ptrdiff_t i1, ptrdiff_t j0, ptrdiff_t j1, const double *x,
         const double *r, const double *nx, const double *nr, const double *w, ptrdiff_t ld,
         const unsigned char *skip, double *restrict S, double *restrict D)
{
    double dx[TILE][TILE], dr[TILE][TILE], d2[TILE][TILE], K[TILE][TILE], E[TILE][TILE], inv[TILE][TILE];
    double Dd[TILE], q[TILE], lnq[TILE];
    /* the source's normal x-component and the partner's dx: negated for an image (exact) */
    const double nsign = xs ? -1.0 : 1.0;
    for (ptrdiff_t i = i0; i < i1; i++) {
        ptrdiff_t a = i - i0, first = j0 > i ? j0 : i;
        int m = (int)(j1 - first);
        if (m <= 0)
            continue;
        const double xi = x[i], ri = r[i];
        double *tdx = dx[a] + (first - j0), *tdr = dr[a] + (first - j0), *td2 = d2[a] + (first - j0);
        double *tK = K[a] + (first - j0), *tE = E[a] + (first - j0), *tinv = inv[a] + (first - j0);
        for (int k = 0; k < m; k++) {
            double s = ri + r[first + k];
            tdx[k] = xi - (xs ? xs : x)[first + k];
            tdr[k] = ri - r[first + k];
            td2[k] = tdx[k] * tdx[k] + tdr[k] * tdr[k];
            Dd[k] = tdx[k] * tdx[k] + s * s;
            q[k] = td2[k] / Dd[k];
        }
        for (int k = 0; k < m; k++)
            lnq[k] = log(q[k]);
        for (int k = 0; k < m; k++) {
            ellip_ke(q[k], lnq[k], tK + k, tE + k);
            tinv[k] = 1.0 / (PI * sqrt(Dd[k]));
        }
        double *Si = S + i * ld + first, *Di = D + i * ld + first;
        for (int k = 0; k < m; k++) {  /* target i, source j = first + k (or its image) */
            ptrdiff_t j = first + k;
            if (skip && skip[i] && skip[j])
                continue;
            double sv, dv;
            ring_layers(tK[k], tE[k], tinv[k], td2[k], tdx[k], tdr[k], r[j], nsign * nx[j], nr[j], &sv, &dv);
            Si[k] = sv * w[j];
            Di[k] = dv * w[j];
        }
    }
    for (ptrdiff_t j = j0; j < j1; j++) {  /* target j, source i < j (or its image): dr is -dr */
        ptrdiff_t b = j - j0, last = j < i1 ? j : i1;
        double *Sj = S + j * ld, *Dj = D + j * ld;
        for (ptrdiff_t i = i0; i < last; i++) {
            ptrdiff_t a = i - i0;
            if (skip && skip[i] && skip[j])
                continue;
            double sv, dv;
            ring_layers(K[a][b], E[a][b], inv[a][b], d2[a][b], -nsign * dx[a][b], -dr[a][b], r[i], nsign * nx[i],
                        nr[i], &sv, &dv);
            Sj[i] = sv * w[i];
            Dj[i] = dv * w[i];
        }
    }
}

/* The tiles of the pairs j >= i of n nodes (sym_tile); a tile of skipped pairs only is left out. */
static inline __attribute__((always_inline)) void
sym_tiles(const double *xs, ptrdiff_t n, const double *x, const double *r, const double *nx,
          const double *nr, const double *w, ptrdiff_t ld, const unsigned char *skip, double *S, double *D)
{
    for (ptrdiff_t i0 = 0; i0 < n; i0 += TILE) {
        ptrdiff_t i1 = i0 + TILE < n ? i0 + TILE : n;
        for (ptrdiff_t j0 = i0; j0 < n; j0 += TILE) {
            ptrdiff_t j1 = j0 + TILE < n ? j0 + TILE : n;
            if (skip) {  /* a tile of skipped pairs only: nothing to do */
                int all = 1;
                for (ptrdiff_t i = i0; i < i1 && all; i++)
                    all = skip[i] != 0;
                for (ptrdiff_t j = j0; j < j1 && all; j++)
                    all = skip[j] != 0;
                if (all)
                    continue;
            }
            sym_tile(xs, i0, i1, j0, j1, x, r, nx, nr, w, ld, skip, S, D);
        }
    }
}

WIDE void ring_dense_sym(ptrdiff_t n, const double *x, const double *r, const double *nx, const double *nr,
                    const double *w, ptrdiff_t ld, const unsigned char *skip, double *S, double *D)
{
    sym_tiles(NULL, n, x, r, nx, nr, w, ld, skip, S, D);
}

/* The nodes (x, r) (normals (nx, nr), weights w) against the images of the same nodes in the free surface
 * (the half-space's mirror surface S': the image of node j at x = xs[j], the same r and weight, the normal
 * (-nx, nr)), column j the image of node j: S[i, j], D[i, j] (rows ld apart) of ring_layers times w[j].
 * The modulus is symmetric in the pair (x_i - x*_j = x_j - x*_i = x_i + x_j - 2 x_surface, s = r_i + r_j;
 * dr only changes sign), so q, ln q, K, E and 1/(pi sqrt D) are computed once per pair {i, j} (i <= j, from
 * dx = x_i - xs[j]) and give both (i, j*) and (j, i*) (this project's own shortcut, as ring_dense_sym).
 * Every entry is the arithmetic of ring_dense with the differences formed so. */
WIDE void ring_dense_mirror_sym(ptrdiff_t n, const double *x, const double *r, const double *nx, const double *nr,
                           const double *w, const double *xs, ptrdiff_t ld, double *S, double *D)
{
    sym_tiles(xs, n, x, r, nx, nr, w, ld, NULL, S, D);
}

/* Row k of ws, wd (point s0 + k) times its Lagrange row into row pair[s0 + k] of outS, outD:
 * the rows of a block are consecutive in `rows` (Q == 0) or repeat every Q points (Q > 0, one
 * matrix shared by the block's pairs).  P is a constant where inlined (the compiler unrolls). */
static inline __attribute__((always_inline)) void
accumulate(ptrdiff_t s0, ptrdiff_t s1, ptrdiff_t Q, const double *rows, const ptrdiff_t *pair,
           const double *ws, const double *wd, ptrdiff_t P, double *restrict outS, double *restrict outD)
{
    ptrdiff_t q = 0;
    for (ptrdiff_t k = s0; k < s1; k++) {
        const double *row = rows + (Q ? q : k - s0) * P;
        double *os = outS + pair[k] * P, *od = outD + pair[k] * P;
        double a = ws[k], b = wd[k];
        for (ptrdiff_t c = 0; c < P; c++) {
            os[c] += a * row[c];
            od[c] += b * row[c];
        }
        if (Q && ++q == Q)
            q = 0;
    }
}

/* The near and self rules of PairQuadrature.integrate (semianalytic/bem/solve.py) after the
 * panel geometry: for each of n quadrature points k, the source point (x, r) and its
 * derivative (xu, ru) d/du (point j = index[k] of the arrays, or k when index is NULL), the
 * Jacobian J = |(xu, ru)| and normal (ru, -xu)/J, the target (xt, rt)[tgt[k]] (or the
 * differences ddx, ddr[k] when given), the kernels S, Dl of single_double, weighted
 * (a S + b QS) J and (a Dl + b QD) J with the split kernels when b != NULL, else a S J and
 * a Dl J (into work[0 .. 2n-1]), summed against the point's Lagrange row into row pair[k] of
 * the (n_pairs, p) blocks outS, outD (zeroed by the caller).  The rows come in nblk blocks of
 * points bstart[i] .. bstart[i + 1] - 1 with rows brows[i] (consecutive, bq[i] == 0, or
 * repeating every bq[i] points).  With tiny != NULL, the points k with tiny[k] != 0 (on panels
 * graded far below their distance from the origin) take their differences through the anchors:
 * (tsplit[0][t] - psplit[0][j]) + (tsplit[2][t] - psplit[2][j]) and likewise in r with [1], [3],
 * psplit the points' (anchor x, anchor r, offset x, offset r), tsplit the targets'.  With flat != NULL
 * the nflat entries of the blocks are then also written to intoS, intoD at the flat indices flat[i]. */
WIDE void ring_pair_rules(ptrdiff_t n, const ptrdiff_t *index, const double *x, const double *r,
                     const double *xu, const double *ru, const ptrdiff_t *tgt, const double *xt,
                     const double *rt, const double *ddx, const double *ddr, const double *a,
                     const double *b, const ptrdiff_t *pair, ptrdiff_t nblk, const ptrdiff_t *bstart,
                     const ptrdiff_t *bq, const double *const *brows, ptrdiff_t p, double *work,
                     double *outS, double *outD, const unsigned char *tiny,
                     const double *const *psplit, const double *const *tsplit, ptrdiff_t nsrc,
                     double *geo, ptrdiff_t nflat, const ptrdiff_t *flat, double *intoS, double *intoD)
{
    double dx[BLK], dr[BLK], s[BLK], r1[BLK], nx1[BLK], nr1[BLK], J[BLK];
    double S[BLK], Dl[BLK], QS[BLK], QD[BLK];
    double *ws = work, *wd = work + n;
    /* with index and geo (3 nsrc doubles): the Jacobian and normal of each of the nsrc source
     * points once, shared by the points that index it (the same numbers) */
    double *gJ = NULL, *gnx = NULL, *gnr = NULL;
    if (index && geo) {
        gJ = geo, gnx = geo + nsrc, gnr = geo + 2 * nsrc;
        for (ptrdiff_t j = 0; j < nsrc; j++) {
            double Jk = hypot(xu[j], ru[j]);
            gJ[j] = Jk;
            gnx[j] = ru[j] / Jk;
            gnr[j] = -xu[j] / Jk;
        }
    }
    for (ptrdiff_t a0 = 0; a0 < n; a0 += BLK) {
        int m = n - a0 < BLK ? (int)(n - a0) : BLK;
        for (int i = 0; i < m; i++) {
            ptrdiff_t k = a0 + i, j = index ? index[k] : k, t = tgt[k];
            double xs = x[j], rs = r[j];
            if (gJ) {
                J[i] = gJ[j];
                nx1[i] = gnx[j];
                nr1[i] = gnr[j];
            } else {
                double xus = xu[j], rus = ru[j];
                double Jk = hypot(xus, rus);
                J[i] = Jk;
                nx1[i] = rus / Jk;
                nr1[i] = -xus / Jk;
            }
            r1[i] = rs;
            if (tiny && tiny[k]) {
                dx[i] = (tsplit[0][t] - psplit[0][j]) + (tsplit[2][t] - psplit[2][j]);
                dr[i] = (tsplit[1][t] - psplit[1][j]) + (tsplit[3][t] - psplit[3][j]);
            } else {
                dx[i] = ddx ? ddx[k] : xt[t] - xs;
                dr[i] = ddr ? ddr[k] : rt[t] - rs;
            }
            s[i] = rt[t] + rs;
        }
        block(m, dx, dr, s, r1, nx1, nr1, NULL, S, Dl, b ? QS : NULL, b ? QD : NULL);
        if (b)
            for (int i = 0; i < m; i++) {
                ws[a0 + i] = (a[a0 + i] * S[i] + b[a0 + i] * QS[i]) * J[i];
                wd[a0 + i] = (a[a0 + i] * Dl[i] + b[a0 + i] * QD[i]) * J[i];
            }
        else
            for (int i = 0; i < m; i++) {
                ws[a0 + i] = a[a0 + i] * S[i] * J[i];
                wd[a0 + i] = a[a0 + i] * Dl[i] * J[i];
            }
    }
    for (ptrdiff_t i = 0; i < nblk; i++) {
        ptrdiff_t s0 = bstart[i], s1 = bstart[i + 1];
        switch (p) {
        case 4: accumulate(s0, s1, bq[i], brows[i], pair, ws, wd, 4, outS, outD); break;
        case 6: accumulate(s0, s1, bq[i], brows[i], pair, ws, wd, 6, outS, outD); break;
        case 8: accumulate(s0, s1, bq[i], brows[i], pair, ws, wd, 8, outS, outD); break;
        default: accumulate(s0, s1, bq[i], brows[i], pair, ws, wd, p, outS, outD);
        }
    }
    /* with flat != NULL: entry i of the blocks (n_pairs * p = nflat of them) written to intoS, intoD at
     * flat[i] (numpy's put, without its per-call overhead: the caller checked the indices) */
    if (flat)
        for (ptrdiff_t i = 0; i < nflat; i++) {
            intoS[flat[i]] = outS[i];
            intoD[flat[i]] = outD[i];
        }
}

/* The panel geometry of PanelSet (semianalytic/bem/panels.py) on lines, circular arcs,
 * ellipse arcs and a table nose's cubic spline (kind 3, spline_interval and spline_at below), the same formulas in the same order as PanelSet._param, _evaluate_segment,
 * relative and the segments' displacement and derivative (semianalytic/geometry.py).  Per
 * panel k: segment parameter of the anchor base, offsets da, db of the ends, half = (db - da)/2,
 * sign, anchor (ax, ar), the corner substitution (cluster -1, 0 or +1 and power; cluster NULL:
 * none), the curve kind (0 line with c0, c1 = p1 - p0; 1 arc with c0 = radius; 2 ellipse arc
 * with semi-axes c0, c1; 3 the spline of P->knots, cx, cr). */
typedef struct {
    const double *base, *da, *db, *half, *sign, *ax, *ar, *cluster, *power, *c0, *c1;
    const ptrdiff_t *kind;
    double offset;
    /* kind 3: the cubic splines x(s), r(s) of a table nose (one per panel set): knots and the
     * power-basis coefficients (4, nk - 1), highest power first, of scipy's CubicSpline */
    ptrdiff_t nk;
    const double *knots, *cx, *cr;
} panels_t;

/* scipy's PPoly evaluation of a cubic (scipy/interpolate/_ppoly.pyx: find_interval_ascending
 * with extrapolation, evaluate_poly1), operation for operation so that the numbers are the
 * same, in two parts so that the derivatives at a point share its search: spline_interval, the
 * interval with knots[i] <= t < knots[i+1] (the last one closed; outside, the end intervals;
 * -1 for NaN), and spline_at, with s = t - knots[i], the terms summed from the lowest power up
 * as res + c z prefactor with z = s^k built by products.  nu = 0, 1 or 2. */
static inline ptrdiff_t spline_interval(const panels_t *P, double t)
{
    ptrdiff_t nk = P->nk, i;
    double a = P->knots[0], b = P->knots[nk - 1];
    if (!(a <= t && t <= b)) {
        if (t < a) i = 0;
        else if (t > b) i = nk - 2;
        else i = -1;  /* NaN */
    } else if (t == b) {
        i = nk - 2;
    } else {
        ptrdiff_t lo = 0, hi = nk - 2;  /* the largest i with knots[i] <= t */
        while (lo < hi) {
            ptrdiff_t mid = (lo + hi + 1) / 2;
            if (P->knots[mid] <= t) lo = mid; else hi = mid - 1;
        }
        i = lo;
    }
    return i;
}

/* The cubic of interval i (spline_interval; -1: NaN) at t. */
static inline void spline_at(const panels_t *P, ptrdiff_t i, double t, int nu, double *x, double *r)
{
    ptrdiff_t m = P->nk - 1;
    if (i < 0) {
        *x = NAN;
        *r = NAN;
        return;
    }
    double s = t - P->knots[i];
    const double *cs[2] = {P->cx, P->cr};
    double out[2];
    for (int j = 0; j < 2; j++) {
        const double *c = cs[j];
        double c0 = c[i], c1 = c[m + i], c2 = c[2 * m + i], c3 = c[3 * m + i];
        double res = 0.0, z = 1.0;
        if (nu == 0) {
            res = res + c3 * z * 1.0;
            z *= s;
            res = res + c2 * z * 1.0;
            z *= s;
            res = res + c1 * z * 1.0;
            z *= s;
            res = res + c0 * z * 1.0;
        } else if (nu == 1) {
            res = res + c2 * z * 1.0;
            z *= s;
            res = res + c1 * z * 2.0;
            z *= s;
            res = res + c0 * z * 3.0;
        } else {  /* nu = 2: the prefactors 2 * 1 and 3 * 2 */
            res = res + c1 * z * 2.0;
            z *= s;
            res = res + c0 * z * 6.0;
        }
        out[j] = res;
    }
    *x = out[0];
    *r = out[1];
}

/* The spline's point at the last anchor parameter t of a loop over points (the points of a panel come
 * together and share their anchor): evaluated once, not once per point (the same numbers). */
typedef struct {
    double t, x, r;
    int ok;
} anchor_t;

/* Offset dt of the segment parameter from the anchor at u, and d dt/du (PanelSet._param). */
static inline double param(const panels_t *P, ptrdiff_t k, double uu, double *dtdu)
{
    double dt = P->da[k] + P->half[k] * (uu + 1.0);
    *dtdu = P->half[k];
    if (P->cluster && P->cluster[k] != 0.0) {
        double c = P->cluster[k], q = P->power[k], span = P->db[k] - P->da[k];
        double lo = 0.5 * (1.0 - c * uu);
        double sw = span * pow(lo, q);
        dt = c > 0 ? P->db[k] - sw : P->da[k] + sw;
        *dtdu = 0.5 * span * q * pow(lo, q - 1.0);
    }
    return dt;
}

/* point(t + dt) - point(t) of the curve of panel k (the segments' displacement).  On a spline: the
 * point at t from `an` when it holds t (NULL: none kept), and the interval of t + dt written to *iend
 * (for the derivatives there). */
static inline void displacement(const panels_t *P, ptrdiff_t k, double t, double dt, double *ex, double *er,
                                anchor_t *an, ptrdiff_t *iend)
{
    if (P->kind[k] == 0) {
        *ex = P->c0[k] * dt;
        *er = P->c1[k] * dt;
    } else if (P->kind[k] == 1) {
        double s2 = 2.0 * P->c0[k] * sin(0.5 * dt), mid = t + 0.5 * dt;
        *ex = -s2 * sin(mid);
        *er = s2 * cos(mid);
    } else if (P->kind[k] == 3) {  /* SplineCurve.displacement: by difference */
        double x0, r0, x1, r1, te = t + dt;
        if (an && an->ok && an->t == t) {
            x0 = an->x;
            r0 = an->r;
        } else {
            spline_at(P, spline_interval(P, t), t, 0, &x0, &r0);
            if (an) {
                an->t = t, an->x = x0, an->r = r0;
                an->ok = 1;
            }
        }
        ptrdiff_t i1 = spline_interval(P, te);
        spline_at(P, i1, te, 0, &x1, &r1);
        if (iend)
            *iend = i1;
        *ex = x1 - x0;
        *er = r1 - r0;
    } else {
        double s2 = 2.0 * sin(0.5 * dt), mid = t + 0.5 * dt;
        *ex = -P->c0[k] * s2 * sin(mid);
        *er = P->c1[k] * s2 * cos(mid);
    }
}

/* PanelSet.evaluate at one point: x, r, x_u, r_u (out[0..3]) at u on panel k, and the
 * displacement (ex, er) from the anchor. */
static inline void point_first(const panels_t *P, ptrdiff_t k, double uu, double *out, double *ex, double *er,
                               anchor_t *an)
{
    double dtdu, dt = param(P, k, uu, &dtdu), t = P->base[k], dx, dr, c0 = P->c0[k], c1 = P->c1[k];
    ptrdiff_t iend = -1;
    displacement(P, k, t, dt, ex, er, an, &iend);
    if (P->kind[k] == 0) {  /* the derivative at t + dt */
        dx = c0;
        dr = c1;
    } else if (P->kind[k] == 1) {
        dx = -c0 * sin(t + dt);
        dr = c0 * cos(t + dt);
    } else if (P->kind[k] == 3) {
        spline_at(P, iend, t + dt, 1, &dx, &dr);
    } else {
        dx = -c0 * sin(t + dt);
        dr = c1 * cos(t + dt);
    }
    double sg = P->sign[k];
    out[0] = sg * (P->ax[k] + *ex) + (sg - 1.0) * P->offset;
    out[1] = P->ar[k] + *er;
    out[2] = sg * dx * dtdu;
    out[3] = dr * dtdu;
}

/* PanelSet.evaluate: point i on panel k = panel[i] at the reference coordinate u[i]; writes x,
 * r, x_u, r_u and, with sax != NULL, the split (anchor, offset) of PanelSet.split. */
void ring_panel_points(ptrdiff_t n, const ptrdiff_t *panel, const double *u, const double *base,
                       const double *da, const double *db, const double *half, const double *sign,
                       const double *ax, const double *ar, double offset, const double *cluster,
                       const double *power, const ptrdiff_t *kind, const double *c0, const double *c1,
                       ptrdiff_t nk, const double *knots, const double *cx, const double *cr,
                       double *x, double *r, double *xu, double *ru,
                       double *sax, double *sar, double *sex, double *ser)
{
    panels_t P = {base, da, db, half, sign, ax, ar, cluster, power, c0, c1, kind, offset, nk, knots, cx, cr};
    double o[4];
    anchor_t an = {0.0, 0.0, 0.0, 0};
    for (ptrdiff_t i = 0; i < n; i++) {
        ptrdiff_t k = panel[i];
        double ex, er;
        point_first(&P, k, u[i], o, &ex, &er, &an);
        x[i] = o[0];
        r[i] = o[1];
        xu[i] = o[2];
        ru[i] = o[3];
        if (sax) {
            double sg = sign[k];
            sax[i] = sg * ax[k] + (sg - 1.0) * offset;
            sar[i] = ar[k];
            sex[i] = sg * ex;
            ser[i] = er;
        }
    }
}

/* PanelSet.relative: point(u_to[i]) - point(u_from[i]) on panel[i], free of cancellation. */
void ring_panel_relative(ptrdiff_t n, const ptrdiff_t *panel, const double *u_from, const double *u_to,
                         const double *base, const double *da, const double *db, const double *half,
                         const double *sign, const double *cluster, const double *power,
                         const ptrdiff_t *kind, const double *c0, const double *c1,
                         ptrdiff_t nk, const double *knots, const double *cx, const double *cr, double *dx, double *dr)
{
    panels_t P = {base, da, db, half, sign, NULL, NULL, cluster, power, c0, c1, kind, 0.0, nk, knots, cx, cr};
    for (ptrdiff_t i = 0; i < n; i++) {
        ptrdiff_t k = panel[i];
        double uf = u_from[i], ut = u_to[i], t_from, step, ex, er;
        if (cluster && cluster[k] != 0.0) {
            double d1, dt_from = param(&P, k, uf, &d1);
            t_from = base[k] + dt_from;
            step = param(&P, k, ut, &d1) - dt_from;
        } else {
            t_from = base[k] + da[k] + half[k] * (uf + 1.0);
            step = half[k] * (ut - uf);
        }
        displacement(&P, k, t_from, step, &ex, &er, NULL, NULL);
        dx[i] = sign[k] * ex;
        dr[i] = er;
    }
}

/* PanelSet.evaluate(..., second=True) at one point: x, r, x_u, r_u, x_uu, r_uu (out[0..5]) at u
 * on panel k, the formulas of PanelSet._param (with its d2t) and _evaluate_segment's second
 * branch in numpy's order, the segments' second_derivative (line 0, arc -R (cos, sin), ellipse
 * (-a cos, -b sin), spline_at with nu = 2).  On a corner panel w[0..2] are numpy's lo^q,
 * lo^(q - 1) and lo^max(q - 2, 0) at the point (numpy's power differs from libm's pow by an
 * ulp at times, and this replicates the numpy path; w is read on corner panels only). */
static inline void point_second(const panels_t *P, ptrdiff_t k, double uu, const double *w, double *out)
{
    double dt = P->da[k] + P->half[k] * (uu + 1.0), dtdu = P->half[k], d2t = 0.0;
    if (P->cluster && P->cluster[k] != 0.0) {
        double c = P->cluster[k], q = P->power[k], span = P->db[k] - P->da[k];
        double sw = span * w[0];
        dt = c > 0 ? P->db[k] - sw : P->da[k] + sw;
        dtdu = 0.5 * span * q * w[1];
        double d2w = 0.25 * q * (q - 1.0) * w[2];
        d2t = c > 0 ? -span * d2w : span * d2w;
    }
    double t = P->base[k], ex, er, dx, dr, ddx, ddr, c0 = P->c0[k], c1 = P->c1[k];
    ptrdiff_t iend = -1;
    displacement(P, k, t, dt, &ex, &er, NULL, &iend);
    if (P->kind[k] == 0) {
        dx = c0;
        dr = c1;
        ddx = 0.0;
        ddr = 0.0;
    } else if (P->kind[k] == 1) {
        dx = -c0 * sin(t + dt);
        dr = c0 * cos(t + dt);
        ddx = -c0 * cos(t + dt);
        ddr = -c0 * sin(t + dt);
    } else if (P->kind[k] == 3) {
        spline_at(P, iend, t + dt, 1, &dx, &dr);
        spline_at(P, iend, t + dt, 2, &ddx, &ddr);
    } else {
        dx = -c0 * sin(t + dt);
        dr = c1 * cos(t + dt);
        ddx = -c0 * cos(t + dt);
        ddr = -c1 * sin(t + dt);
    }
    double sg = P->sign[k];
    out[0] = sg * (P->ax[k] + ex) + (sg - 1.0) * P->offset;
    out[1] = P->ar[k] + er;
    out[2] = sg * dx * dtdu;
    out[3] = dr * dtdu;
    out[4] = sg * (ddx * dtdu * dtdu + dx * d2t);
    out[5] = ddr * dtdu * dtdu + dr * d2t;
}

/* PanelSet.evaluate(..., second=True) (point_second) at point i on panel[i]; pw: (n, 3), rows
 * of point_second's w (NULL without corner points). */
void ring_panel_second(ptrdiff_t n, const ptrdiff_t *panel, const double *u, const double *base,
                       const double *da, const double *db, const double *half, const double *sign,
                       const double *ax, const double *ar, double offset, const double *cluster,
                       const double *power, const ptrdiff_t *kind, const double *c0, const double *c1,
                       ptrdiff_t nk, const double *knots, const double *cx, const double *cr, const double *pw,
                       double *x, double *r, double *xu, double *ru, double *xuu, double *ruu)
{
    panels_t P = {base, da, db, half, sign, ax, ar, cluster, power, c0, c1, kind, offset, nk, knots, cx, cr};
    double o[6];
    for (ptrdiff_t i = 0; i < n; i++) {
        point_second(&P, panel[i], u[i], pw ? pw + 3 * i : NULL, o);
        x[i] = o[0];
        r[i] = o[1];
        xu[i] = o[2];
        ru[i] = o[3];
        xuu[i] = o[4];
        ruu[i] = o[5];
    }
}

/* One Newton step of closest_points (semianalytic/bem/solve.py, _newton) on
 * (y(u) - x) . y'(u) = 0 from u on panel k towards the point (X, R), projected onto [-1, 1] as
 * numpy's clip does (NaN stays); w as in point_second. */
static inline double newton_step(const panels_t *P, ptrdiff_t k, double uu, double X, double R, const double *w)
{
    double o[6];
    point_second(P, k, uu, w, o);
    double ex = o[0] - X, er = o[1] - R;
    double fn = ex * o[2] + er * o[3];
    double fp = o[2] * o[2] + o[3] * o[3] + ex * o[4] + er * o[5];
    double step = fp > 0 ? fn / fp : 0.0;
    double v = uu - step;
    if (!(v != v)) v = v < -1.0 ? -1.0 : (v > 1.0 ? 1.0 : v);
    return v;
}

/* newton_step at each pair i (u updated in place); pw as in ring_panel_second.  With ex != NULL,
 * also the point at the new u (point_first, as PanelSet.evaluate computes it): x - xq, r - rq,
 * x_u, r_u. */
void ring_newton_step(ptrdiff_t n, const ptrdiff_t *pan, double *u, const double *xq, const double *rq,
                      const double *base, const double *da, const double *db, const double *half, const double *sign,
                      const double *ax, const double *ar, double offset, const double *cluster,
                      const double *power, const ptrdiff_t *kind, const double *c0, const double *c1,
                      ptrdiff_t nk, const double *knots, const double *cx, const double *cr, const double *pw,
                      double *ex, double *er, double *xu, double *ru)
{
    panels_t P = {base, da, db, half, sign, ax, ar, cluster, power, c0, c1, kind, offset, nk, knots, cx, cr};
    for (ptrdiff_t i = 0; i < n; i++) {
        u[i] = newton_step(&P, pan[i], u[i], xq[i], rq[i], pw ? pw + 3 * i : NULL);
        if (ex) {
            double o[4], e1, e2;
            point_first(&P, pan[i], u[i], o, &e1, &e2, NULL);
            ex[i] = o[0] - xq[i];
            er[i] = o[1] - rq[i];
            xu[i] = o[2];
            ru[i] = o[3];
        }
    }
}

/* closest_points (semianalytic/bem/solve.py) on the panels without a corner substitution, the
 * same operations in the same order: the nearest of the ns samples of the panel's table
 * (stx, str, stxu, stru: x, r, x_u, r_u, each (n_panels, ns); numpy's argmin, the first NaN or
 * else the first minimum), the end test, two Newton steps on (y(u) - x) . y'(u) = 0 projected
 * onto [-1, 1] (numpy's clip: NaN stays), the point at the result.  Writes u, ex = x - xq,
 * er = r - rq, x_u, r_u; a pair that needs Newton steps on a corner panel gets todo[i] = 1 and
 * its sample's values (the caller steps it with numpy's power, which pow here would miss by
 * an ulp at times), the others todo[i] = 0. */
void ring_closest_points(ptrdiff_t n, const ptrdiff_t *pan, const double *xq, const double *rq,
                         ptrdiff_t ns, const double *samples, const double *stx, const double *str,
                         const double *stxu, const double *stru, const double *base,
                         const double *da, const double *db, const double *half, const double *sign,
                         const double *ax, const double *ar, double offset, const double *cluster,
                         const double *power, const ptrdiff_t *kind, const double *c0, const double *c1,
                         ptrdiff_t nk, const double *knots, const double *cx, const double *cr,
                         double *u, double *ex, double *er, double *xu, double *ru, signed char *todo)
{
    panels_t P = {base, da, db, half, sign, ax, ar, cluster, power, c0, c1, kind, offset, nk, knots, cx, cr};
    for (ptrdiff_t i = 0; i < n; i++) {
        ptrdiff_t k = pan[i], row = k * ns, j = 0;
        double X = xq[i], R = rq[i], best = 0.0;
        for (ptrdiff_t m = 0; m < ns; m++) {
            double a = stx[row + m] - X, b = str[row + m] - R;
            double d2 = a * a + b * b;
            if (d2 != d2) {  /* numpy's argmin: the first NaN */
                j = m;
                break;
            }
            if (m == 0 || d2 < best) {
                best = d2;
                j = m;
            }
        }
        double uu = samples[j], x = stx[row + j], r = str[row + j], dx = stxu[row + j], dr = stru[row + j];
        double f = (x - X) * dx + (r - R) * dr;
        int settled = (j == 0 && f >= 0) || (j == ns - 1 && f <= 0);
        todo[i] = 0;
        if (!settled) {
            if (cluster && cluster[k] != 0.0) {
                todo[i] = 1;
            } else {
                double o[4], e1, e2;
                for (int it = 0; it < 2; it++)
                    uu = newton_step(&P, k, uu, X, R, NULL);
                point_first(&P, k, uu, o, &e1, &e2, NULL);
                x = o[0];
                r = o[1];
                dx = o[2];
                dr = o[3];
            }
        }
        u[i] = uu;
        ex[i] = x - X;
        er[i] = r - R;
        xu[i] = dx;
        ru[i] = dr;
    }
}
