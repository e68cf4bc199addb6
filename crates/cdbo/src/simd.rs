//! Runtime choice of wider vector instructions for the hottest loops.
//!
//! The crate is built for the baseline x86-64 (two doubles per SSE2 instruction). Where the
//! processor has AVX2, [`wide`] runs a closure compiled for it, so that the loops inside
//! vectorise four doubles wide. No multiply and add are fused (FMA stays off), so the results
//! are the same bit for bit on every x86-64 processor.
//!
//! The GP's one-point triangular solve, the innermost loop of CDBO's coordinate ascent, is
//! written out with AVX2 intrinsics ([`TriangularRows::forward_substitute`], [`dot4`]),
//! beside a portable version that sums in the same order.

/// Runs `f`, compiled for AVX2 when the processor has it.
#[inline(always)]
pub fn wide<R>(f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx2")]
        fn avx2<R>(f: impl FnOnce() -> R) -> R {
            f()
        }
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2, checked just above.
            return unsafe { avx2(f) };
        }
    }
    f()
}

/// A lower-triangular factor L kept for fast one-point solves ([`Self::forward_substitute`]).
///
/// Its rows are packed (row i, its i + 1 entries up to the diagonal, starts at i(i + 1)/2),
/// with the reciprocals of the diagonal. Each complete group of four rows 4b … 4b + 3 is also
/// stored interleaved over its first c_b = 8⌊4b/8⌋ columns, by chunks of eight columns (row
/// 4b's eight entries, then row 4b + 1's, 4b + 2's, 4b + 3's, then the next chunk), the groups
/// one after the other: a solve then reads the factor as one stream rather than four.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangularRows {
    rows: Vec<f64>,
    inv_diag: Vec<f64>,
    groups: Vec<f64>,
}

impl TriangularRows {
    /// The factor of `n` rows whose entry (i, j), j ≤ i, is `entry(i, j)`.
    pub fn from_fn(n: usize, entry: impl Fn(usize, usize) -> f64) -> TriangularRows {
        let mut l = TriangularRows::default();
        let mut row = Vec::with_capacity(n);
        for i in 0..n {
            row.clear();
            row.extend((0..=i).map(|j| entry(i, j)));
            l.push_row(&row);
        }
        l
    }

    /// Rows.
    pub fn len(&self) -> usize {
        self.inv_diag.len()
    }

    /// Appends row n = len(): its n + 1 entries, the diagonal last.
    pub fn push_row(&mut self, row: &[f64]) {
        let i = self.len();
        assert_eq!(
            row.len(),
            i + 1,
            "row {i} of a triangular factor has {} entries",
            i + 1
        );
        self.rows.extend_from_slice(row);
        self.inv_diag.push(1.0 / row[i]);
        if i % 4 == 3 {
            let first = i - 3;
            for c in (0..first / 8 * 8).step_by(8) {
                for r in first..=i {
                    let start = r * (r + 1) / 2 + c;
                    self.groups.extend_from_slice(&self.rows[start..start + 8]);
                }
            }
        }
    }

    fn row(&self, i: usize) -> &[f64] {
        &self.rows[i * (i + 1) / 2..(i + 1) * (i + 2) / 2]
    }

    /// Overwrites k (len() values) by x = L⁻¹k and returns ‖x‖².
    ///
    /// Row-oriented forward substitution, xᵢ = (kᵢ − L[i, ..i]·x[..i]) / Lᵢᵢ, four rows at a
    /// time: their dot products with x[..i] ([`dot4`]'s order of summation, over the
    /// interleaved group then the remaining columns) share each load of x and read the factor
    /// once, in memory order (memory traffic bounds the solve); the 4 × 4 triangle finishes
    /// them. Compiled for AVX2 when the processor has it, with the same result.
    pub fn forward_substitute(&self, k: &mut [f64]) -> f64 {
        #[cfg(target_arch = "x86_64")]
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2, checked just above.
            return unsafe { self.forward_substitute_avx2(k) };
        }
        self.forward_substitute_with(k, dot4_portable, group_dot4_portable)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn forward_substitute_avx2(&self, k: &mut [f64]) -> f64 {
        self.forward_substitute_with(k, |r, x| dot4_avx2(r, x), |g, x| group_dot4_avx2(g, x))
    }

    #[inline(always)]
    fn forward_substitute_with(
        &self,
        k: &mut [f64],
        dot4: impl Fn([&[f64]; 4], &[f64]) -> [f64; 4],
        group_dot4: impl Fn(&[f64], &[f64]) -> [f64; 4],
    ) -> f64 {
        let n = k.len();
        assert_eq!(n, self.len(), "a solve with L of {} rows", self.len());
        let inv = &self.inv_diag;
        let mut vv = 0.0;
        let (mut i, mut offset) = (0, 0);
        while i + 4 <= n {
            let rows = [
                self.row(i),
                self.row(i + 1),
                self.row(i + 2),
                self.row(i + 3),
            ];
            let [_, r1, r2, r3] = rows;
            let full = i / 8 * 8;
            let mut d = group_dot4(&self.groups[offset..offset + 4 * full], &k[..full]);
            offset += 4 * full;
            for (dr, r) in d.iter_mut().zip(rows) {
                for (a, b) in r[full..i].iter().zip(&k[full..i]) {
                    *dr += a * b;
                }
            }
            let x0 = (k[i] - d[0]) * inv[i];
            let x1 = (k[i + 1] - d[1] - r1[i] * x0) * inv[i + 1];
            let x2 = (k[i + 2] - d[2] - r2[i] * x0 - r2[i + 1] * x1) * inv[i + 2];
            let x3 = (k[i + 3] - d[3] - r3[i] * x0 - r3[i + 1] * x1 - r3[i + 2] * x2) * inv[i + 3];
            k[i..i + 4].copy_from_slice(&[x0, x1, x2, x3]);
            vv += x0 * x0 + x1 * x1 + x2 * x2 + x3 * x3;
            i += 4;
        }
        for i in i..n {
            let r = self.row(i);
            let [d, ..] = dot4([r, r, r, r], &k[..i]);
            let x = (k[i] - d) * inv[i];
            k[i] = x;
            vv += x * x;
        }
        vv
    }
}

/// [`dot4`] of an interleaved group of four rows (see [`TriangularRows`]) with x, whose
/// length is a multiple of 8, in portable code.
#[inline(always)]
fn group_dot4_portable(group: &[f64], x: &[f64]) -> [f64; 4] {
    let mut p = [[0.0; 8]; 4];
    for (chunk, xc) in group.chunks_exact(32).zip(x.chunks_exact(8)) {
        for (pr, rc) in p.iter_mut().zip(chunk.chunks_exact(8)) {
            for l in 0..8 {
                pr[l] += rc[l] * xc[l];
            }
        }
    }
    p.map(|pr| {
        let t: [f64; 4] = std::array::from_fn(|l| pr[l] + pr[l + 4]);
        (t[0] + t[1]) + (t[2] + t[3])
    })
}

/// [`group_dot4_portable`] with AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn group_dot4_avx2(group: &[f64], x: &[f64]) -> [f64; 4] {
    use std::arch::x86_64::_mm256_setzero_pd;
    use std::arch::x86_64::{__m256d, _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd};
    assert!(group.len() >= 4 * x.len() && x.len() % 8 == 0);
    let zero = _mm256_setzero_pd();
    let (mut lo, mut hi): ([__m256d; 4], [__m256d; 4]) = ([zero; 4], [zero; 4]);
    for c in (0..x.len()).step_by(8) {
        // SAFETY: c + 8 ≤ x.len() and 4c + 32 ≤ group.len(), asserted above.
        unsafe {
            let (xa, xb) = (
                _mm256_loadu_pd(x.as_ptr().add(c)),
                _mm256_loadu_pd(x.as_ptr().add(c + 4)),
            );
            let chunk = group.as_ptr().add(4 * c);
            for r in 0..4 {
                let row = chunk.add(8 * r);
                lo[r] = _mm256_add_pd(lo[r], _mm256_mul_pd(_mm256_loadu_pd(row), xa));
                hi[r] = _mm256_add_pd(hi[r], _mm256_mul_pd(_mm256_loadu_pd(row.add(4)), xb));
            }
        }
    }
    reduce4(lo, hi)
}

/// The dot products of four rows with x (each row at least as long as x), in one pass that
/// loads each element of x once.
///
/// Order of summation, the same on every processor: row r's products are accumulated in
/// eight partial sums, p[l] over the elements c ≡ l (mod 8) of the leading multiple of 8;
/// then ((p₀ + p₄) + (p₁ + p₅)) + ((p₂ + p₆) + (p₃ + p₇)); then the remaining elements in
/// order. With AVX2 the partial sums are two four-wide vectors per row.
#[cfg(test)]
pub fn dot4(rows: [&[f64]; 4], x: &[f64]) -> [f64; 4] {
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the processor supports AVX2, checked just above.
        return unsafe { dot4_avx2(rows, x) };
    }
    dot4_portable(rows, x)
}

/// [`dot4`] in portable code.
#[inline(always)]
fn dot4_portable(rows: [&[f64]; 4], x: &[f64]) -> [f64; 4] {
    let n = x.len();
    let rows = rows.map(|r| &r[..n]);
    let full = n / 8 * 8;
    let mut p = [[0.0; 8]; 4];
    for c in (0..full).step_by(8) {
        for (pr, r) in p.iter_mut().zip(&rows) {
            for l in 0..8 {
                pr[l] += r[c + l] * x[c + l];
            }
        }
    }
    let mut out = [0.0; 4];
    for ((o, pr), r) in out.iter_mut().zip(&p).zip(rows) {
        let t: [f64; 4] = std::array::from_fn(|l| pr[l] + pr[l + 4]);
        *o = (t[0] + t[1]) + (t[2] + t[3]);
        for (a, b) in r[full..].iter().zip(&x[full..]) {
            *o += a * b;
        }
    }
    out
}

/// [`dot4`] with AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn dot4_avx2(rows: [&[f64]; 4], x: &[f64]) -> [f64; 4] {
    let n = x.len();
    let rows = rows.map(|r| &r[..n]);
    use std::arch::x86_64::_mm256_setzero_pd;
    use std::arch::x86_64::{__m256d, _mm256_add_pd, _mm256_loadu_pd, _mm256_mul_pd};
    let full = x.len() / 8 * 8;
    let zero = _mm256_setzero_pd();
    // lo[r] holds the partial sums p₀..p₃ of row r, hi[r] p₄..p₇.
    let (mut lo, mut hi): ([__m256d; 4], [__m256d; 4]) = ([zero; 4], [zero; 4]);
    for c in (0..full).step_by(8) {
        // SAFETY: c + 8 ≤ full ≤ len for x and for every row (cut to x's length).
        unsafe {
            let (xa, xb) = (
                _mm256_loadu_pd(x.as_ptr().add(c)),
                _mm256_loadu_pd(x.as_ptr().add(c + 4)),
            );
            for r in 0..4 {
                let row = rows[r].as_ptr().add(c);
                lo[r] = _mm256_add_pd(lo[r], _mm256_mul_pd(_mm256_loadu_pd(row), xa));
                hi[r] = _mm256_add_pd(hi[r], _mm256_mul_pd(_mm256_loadu_pd(row.add(4)), xb));
            }
        }
    }
    let mut out = reduce4(lo, hi);
    for (o, r) in out.iter_mut().zip(rows) {
        for (a, b) in r[full..].iter().zip(&x[full..]) {
            *o += a * b;
        }
    }
    out
}

/// The four rows' sums from their partial sums p₀..p₃ (`lo`) and p₄..p₇ (`hi`):
/// tᵣ = (p₀ + p₄, p₁ + p₅, p₂ + p₆, p₃ + p₇); two horizontal adds and one cross-lane add give
/// ((p₀ + p₄) + (p₁ + p₅)) + ((p₂ + p₆) + (p₃ + p₇)) for all four rows.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
fn reduce4(lo: [std::arch::x86_64::__m256d; 4], hi: [std::arch::x86_64::__m256d; 4]) -> [f64; 4] {
    use std::arch::x86_64::{__m256d, _mm256_add_pd, _mm256_hadd_pd};
    use std::arch::x86_64::{_mm256_permute2f128_pd, _mm256_storeu_pd};
    let t: [__m256d; 4] = std::array::from_fn(|r| _mm256_add_pd(lo[r], hi[r]));
    let (h01, h23) = (_mm256_hadd_pd(t[0], t[1]), _mm256_hadd_pd(t[2], t[3]));
    let sums = _mm256_add_pd(
        _mm256_permute2f128_pd::<0x20>(h01, h23),
        _mm256_permute2f128_pd::<0x31>(h01, h23),
    );
    let mut out = [0.0; 4];
    // SAFETY: out holds four doubles.
    unsafe { _mm256_storeu_pd(out.as_mut_ptr(), sums) };
    out
}

/// The dot product a·b (b at least as long as a), summed in the order of [`dot4`].
#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let b = &b[..a.len()];
    wide(
        #[inline(always)]
        || {
            let full = a.len() / 8 * 8;
            let mut p = [0.0; 8];
            for (ac, bc) in a[..full].chunks_exact(8).zip(b[..full].chunks_exact(8)) {
                for l in 0..8 {
                    p[l] += ac[l] * bc[l];
                }
            }
            let t: [f64; 4] = std::array::from_fn(|l| p[l] + p[l + 4]);
            let mut s = (t[0] + t[1]) + (t[2] + t[3]);
            for (x, y) in a[full..].iter().zip(&b[full..]) {
                s += x * y;
            }
            s
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn numbers(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    #[test]
    fn dot4_is_the_same_on_every_path_and_equals_the_plain_sums() {
        for n in [0, 1, 7, 8, 9, 31, 64, 203] {
            let rows: Vec<Vec<f64>> = (0..4).map(|r| numbers(n + r, r as u64 + 1)).collect();
            let x = numbers(n, 99);
            let refs = [&rows[0][..], &rows[1][..], &rows[2][..], &rows[3][..]];
            let got = dot4(refs, &x);
            assert_eq!(got, dot4_portable(refs, &x), "n = {n}");
            assert_eq!(dot(&rows[2][..n], &x), got[2], "n = {n}");
            for (r, g) in rows.iter().zip(got) {
                let plain: f64 = r.iter().zip(&x).map(|(a, b)| a * b).sum();
                assert!((g - plain).abs() < 1e-13, "n = {n}: {g} vs {plain}");
            }
        }
    }

    #[test]
    fn forward_substitution_solves_the_triangular_system() {
        for n in [1, 3, 4, 5, 8, 12, 17, 40, 61] {
            // A well-conditioned lower-triangular L, packed by rows.
            let mut l = vec![vec![0.0; n]; n];
            let vals = numbers(n * n, n as u64);
            for i in 0..n {
                for j in 0..i {
                    l[i][j] = 0.3 * vals[i * n + j];
                }
                l[i][i] = 1.0 + vals[i * n + i].abs();
            }
            let factor = TriangularRows::from_fn(n, |i, j| l[i][j]);
            let k = numbers(n, 7);
            let mut x = k.clone();
            let norm2 = factor.forward_substitute(&mut x);
            for i in 0..n {
                let lx: f64 = (0..=i).map(|j| l[i][j] * x[j]).sum();
                assert!((lx - k[i]).abs() < 1e-12, "n {n} row {i}: {lx} vs {}", k[i]);
            }
            let direct: f64 = x.iter().map(|v| v * v).sum();
            assert!((norm2 - direct).abs() < 1e-12 * direct.max(1.0));
            // The portable path, and four-row dot products on the packed rows, agree bit
            // for bit.
            let mut portable = k.clone();
            assert_eq!(
                factor.forward_substitute_with(&mut portable, dot4_portable, group_dot4_portable),
                norm2
            );
            assert_eq!(portable, x);
            let mut packed = k.clone();
            let ungrouped = |g: &[f64], x: &[f64]| {
                let rows: Vec<Vec<f64>> =
                    g.chunks_exact(8)
                        .enumerate()
                        .fold(vec![vec![]; 4], |mut rows, (c, chunk)| {
                            rows[c % 4].extend_from_slice(chunk);
                            rows
                        });
                dot4([&rows[0], &rows[1], &rows[2], &rows[3]], x)
            };
            assert_eq!(
                factor.forward_substitute_with(&mut packed, dot4, ungrouped),
                norm2
            );
            assert_eq!(packed, x);
        }
    }
}
