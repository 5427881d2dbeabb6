/* A tensor train's Chebyshev sum at points, register-blocked with AVX-512 intrinsics.
 *
 * Benchmark only (bench_train_kernel.py compiles it with gcc -O3 -mavx512f -mfma and
 * loads it with ctypes); the package evaluates its trains with numpy (train_sum).
 *
 *   V_k[r1, p] = sum_{r0, m} G_k[r0, m, r1] V_{k-1}[r0, p] T_m(x_{order[k], p}),  V_0 = 1,
 *
 * one SIMD vector of points at a time (16 in float32, 8 in float64), every core in turn
 * with V kept in a few kilobytes: for each block of 8 output ranks, 8 accumulators stay
 * in registers while (r0, m) run, each step one product V[r0] T_m and 8 fused
 * multiply-adds with G's entries broadcast. The cores must be padded with zeros so that
 * every r1 but the last core's (1) is a multiple of 8; the last core is summed as
 * sum_r0 V[r0] (sum_m G[r0, m] T_m) with four independent accumulators.
 *
 * rows: the Chebyshev rows of every axis, stacked (axis a's from rows + row_off[a]),
 * each row P contiguous numbers; out: P doubles.
 */
#include <immintrin.h>

#define RMAX 64
#define MMAX 32

#define TRAIN_SUM(NAME, T, VT, B, LOAD, STORE, SET1, FMA, MUL, ZERO, ADD)                  \
    int NAME(int d, const int *r0s, const int *ms, const int *r1s,                         \
             const T *const *cores, const int *order, const T *rows,                       \
             const long *row_off, long P, double *out)                                     \
    {                                                                                      \
        VT va[RMAX], vb[RMAX], tb[MMAX];                                                   \
        for (int k = 0; k < d; k++)                                                        \
            if (r0s[k] > RMAX || r1s[k] > RMAX || ms[k] > MMAX                             \
                || (k < d - 1 && r1s[k] % 8) || (k == d - 1 && r1s[k] != 1))               \
                return -1;                                                                 \
        for (long p0 = 0; p0 < P; p0 += B) {                                               \
            long nb = P - p0 < B ? P - p0 : B;                                             \
            VT *v = va, *vn = vb;                                                          \
            v[0] = SET1((T)1);                                                             \
            for (int k = 0; k < d; k++) {                                                  \
                int r0 = r0s[k], m = ms[k], r1 = r1s[k];                                   \
                const T *g = cores[k], *tr = rows + row_off[order[k]];                     \
                for (int j = 0; j < m; j++) {                                              \
                    if (nb == B) {                                                         \
                        tb[j] = LOAD(tr + j * P + p0);                                     \
                    } else {                                                               \
                        T tmp[B];                                                          \
                        for (int q = 0; q < B; q++) tmp[q] = q < nb ? tr[j * P + p0 + q] : 0; \
                        tb[j] = LOAD(tmp);                                                 \
                    }                                                                      \
                }                                                                          \
                if (r1 == 1) {                                                             \
                    VT s0 = ZERO(), s1 = ZERO(), s2 = ZERO(), s3 = ZERO();                 \
                    int a = 0;                                                             \
                    for (; a + 4 <= r0; a += 4) {                                          \
                        VT u0 = ZERO(), u1 = ZERO(), u2 = ZERO(), u3 = ZERO();             \
                        const T *g0 = g + (long)a * m, *g1 = g0 + m, *g2 = g1 + m,         \
                                *g3 = g2 + m;                                              \
                        for (int j = 0; j < m; j++) {                                      \
                            u0 = FMA(SET1(g0[j]), tb[j], u0);                              \
                            u1 = FMA(SET1(g1[j]), tb[j], u1);                              \
                            u2 = FMA(SET1(g2[j]), tb[j], u2);                              \
                            u3 = FMA(SET1(g3[j]), tb[j], u3);                              \
                        }                                                                  \
                        s0 = FMA(u0, v[a], s0);                                            \
                        s1 = FMA(u1, v[a + 1], s1);                                        \
                        s2 = FMA(u2, v[a + 2], s2);                                        \
                        s3 = FMA(u3, v[a + 3], s3);                                        \
                    }                                                                      \
                    for (; a < r0; a++) {                                                  \
                        VT u0 = ZERO();                                                    \
                        const T *g0 = g + (long)a * m;                                     \
                        for (int j = 0; j < m; j++) u0 = FMA(SET1(g0[j]), tb[j], u0);      \
                        s0 = FMA(u0, v[a], s0);                                            \
                    }                                                                      \
                    vn[0] = ADD(ADD(s0, s1), ADD(s2, s3));                                 \
                } else {                                                                   \
                    for (int i = 0; i < r1; i += 8) {                                      \
                        VT c0 = ZERO(), c1 = ZERO(), c2 = ZERO(), c3 = ZERO();             \
                        VT c4 = ZERO(), c5 = ZERO(), c6 = ZERO(), c7 = ZERO();             \
                        for (int a = 0; a < r0; a++) {                                     \
                            VT va_ = v[a];                                                 \
                            const T *gg = g + (long)a * m * r1 + i;                        \
                            for (int j = 0; j < m; j++, gg += r1) {                        \
                                VT w = MUL(va_, tb[j]);                                    \
                                c0 = FMA(SET1(gg[0]), w, c0);                              \
                                c1 = FMA(SET1(gg[1]), w, c1);                              \
                                c2 = FMA(SET1(gg[2]), w, c2);                              \
                                c3 = FMA(SET1(gg[3]), w, c3);                              \
                                c4 = FMA(SET1(gg[4]), w, c4);                              \
                                c5 = FMA(SET1(gg[5]), w, c5);                              \
                                c6 = FMA(SET1(gg[6]), w, c6);                              \
                                c7 = FMA(SET1(gg[7]), w, c7);                              \
                            }                                                              \
                        }                                                                  \
                        vn[i] = c0; vn[i + 1] = c1; vn[i + 2] = c2; vn[i + 3] = c3;        \
                        vn[i + 4] = c4; vn[i + 5] = c5; vn[i + 6] = c6; vn[i + 7] = c7;    \
                    }                                                                      \
                }                                                                          \
                VT *swap = v; v = vn; vn = swap;                                           \
            }                                                                              \
            T res[B];                                                                      \
            STORE(res, v[0]);                                                              \
            for (long q = 0; q < nb; q++) out[p0 + q] = (double)res[q];                    \
        }                                                                                  \
        return 0;                                                                          \
    }

TRAIN_SUM(train_sum_f32, float, __m512, 16, _mm512_loadu_ps, _mm512_storeu_ps,
          _mm512_set1_ps, _mm512_fmadd_ps, _mm512_mul_ps, _mm512_setzero_ps, _mm512_add_ps)
TRAIN_SUM(train_sum_f64, double, __m512d, 8, _mm512_loadu_pd, _mm512_storeu_pd,
          _mm512_set1_pd, _mm512_fmadd_pd, _mm512_mul_pd, _mm512_setzero_pd, _mm512_add_pd)
