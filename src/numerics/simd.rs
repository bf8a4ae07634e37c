//! Instruction-set dispatch: the SIMD level the hot loops are compiled for, and the
//! helper that compiles a closure into each level's copy.

/// Lanes of the widest vectors, AVX-512's 8 values of f64: the track pads its arrays to
/// a multiple of it, and the flat path evaluates its integrand this many points at a
/// time.
pub const LANES: usize = 8;

/// Vector instructions the track stepper's loops (and [`crate::sim::Simulation`]'s
/// coupled step) run with. The level is detected once when a track is built
/// ([`SimdLevel::detect`]); [`crate::track::Track::set_simd`] picks another (for benchmarks and for
/// checking that the levels agree). Ordered narrowest first.
///
/// Rounding: the AVX2 and AVX-512 levels fuse the track loops' products and sums
/// (FMA, one rounding each) and give bit-identical results to each other; the
/// baseline rounds every product (no FMA there: the library `fma` would make its
/// track step 15 times slower) and agrees with them to rounding. Nothing outside
/// the track loops is fused at any level.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum SimdLevel {
    /// Whatever the build target allows (SSE2 on x86-64), products rounded.
    Baseline,
    /// AVX2 with FMA: 4 lanes of f64.
    Avx2,
    /// AVX-512F with FMA: 8 lanes of f64 in the track loops and the flat-in-patch
    /// contact (the rest of the coupled step is compiled as for AVX2).
    // On the Sapphire Rapids machines we run on, the track step of the reference case
    // (n = 2) takes about 115 ns against 150 ns with AVX2 (`examples/profile_step`,
    // fast phase of the machine).
    Avx512,
}

impl SimdLevel {
    /// The widest level this CPU supports (AVX2 and AVX-512 need FMA as well).
    pub fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        {
            if !std::arch::is_x86_feature_detected!("fma") {
                return SimdLevel::Baseline;
            }
            if std::arch::is_x86_feature_detected!("avx512f") {
                return SimdLevel::Avx512;
            }
            if std::arch::is_x86_feature_detected!("avx2") {
                return SimdLevel::Avx2;
            }
        }
        SimdLevel::Baseline
    }

    /// Runs `f` compiled for this level: inside a function compiled for AVX-512F or
    /// AVX2 (with FMA), into which `f` and everything it calls `#[inline(always)]` are
    /// inlined. Mark the closure `#[inline(always)]` too: otherwise it stays a
    /// function of its own, compiled for the baseline. Nothing is contracted into FMA
    /// by this; only explicit `mul_add`s fuse.
    #[inline(always)]
    pub fn run<R>(self, f: impl FnOnce() -> R) -> R {
        #[cfg(target_arch = "x86_64")]
        {
            #[target_feature(enable = "avx512f,fma")]
            fn avx512<R>(f: impl FnOnce() -> R) -> R {
                f()
            }
            #[target_feature(enable = "avx2,fma")]
            fn avx2<R>(f: impl FnOnce() -> R) -> R {
                f()
            }
            match self {
                // SAFETY: only levels this CPU reports are ever set or detected
                // (`SimdLevel::detect`, `Track::set_simd`, `Simulation::set_simd`).
                SimdLevel::Avx512 => return unsafe { avx512(f) },
                SimdLevel::Avx2 => return unsafe { avx2(f) },
                SimdLevel::Baseline => {}
            }
        }
        f()
    }

    /// Every level this CPU supports, narrowest first.
    pub fn available() -> Vec<Self> {
        let top = Self::detect();
        [SimdLevel::Baseline, SimdLevel::Avx2, SimdLevel::Avx512]
            .into_iter()
            .filter(|l| *l <= top)
            .collect()
    }
}

/// `f` itself: lets a closure be marked `#[inline(always)]` where it is defined
/// (attributes on closures are allowed only in argument position), so that
/// [`SimdLevel::run`] compiles it into each level's copy.
#[inline(always)]
pub fn inlined<F>(f: F) -> F {
    f
}
