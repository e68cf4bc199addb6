//! Runtime choice of wider vector instructions for the hottest loops.
//!
//! The crate is built for the baseline x86-64 (two doubles per SSE2 instruction). Where the
//! processor has AVX2, [`wide`] runs a closure compiled for it, so that the loops inside
//! vectorise four doubles wide. No multiply and add are fused (FMA stays off), so the results
//! are the same bit for bit on every x86-64 processor.

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
