//! The aligned, phase-blocked storage of the rails and the location of a point on them.

use super::*;

/// One cache line of values.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub(super) struct Line(pub(super) [f64; LANES]);

/// Values starting on a cache line, so that with the guards a whole multiple of
/// [`LANES`] long, every block starts on one too and its centre loads and stores never
/// straddle two lines (a vector that does costs two loads).
#[derive(Debug, Clone)]
pub(super) struct Aligned {
    pub(super) lines: Vec<Line>,
    pub(super) len: usize,
}

impl Aligned {
    /// `len` zeros.
    pub(super) fn zeros(len: usize) -> Self {
        Aligned {
            lines: vec![Line([0.0; LANES]); len.div_ceil(LANES)],
            len,
        }
    }
}

impl std::ops::Deref for Aligned {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        // SAFETY: `Line` is `repr(C)` around `[f64; LANES]`, so the lines are
        // `LANES * lines.len() >= len` contiguous, initialised f64 values.
        unsafe { std::slice::from_raw_parts(self.lines.as_ptr().cast::<f64>(), self.len) }
    }
}

impl std::ops::DerefMut for Aligned {
    fn deref_mut(&mut self) -> &mut [f64] {
        // SAFETY: as in `deref`, and `&mut self` borrows the lines uniquely.
        unsafe { std::slice::from_raw_parts_mut(self.lines.as_mut_ptr().cast::<f64>(), self.len) }
    }
}

/// Node `k` and weight `w` of position `x` (m) on a rail of `nk` nodes spaced
/// `1 / inv_dx`: see [`Track::locate`].
#[inline]
pub(super) fn locate(x: f64, inv_dx: f64, nk: usize) -> (usize, f64) {
    let s = (x * inv_dx).max(0.0);
    // Truncation equals floor for s >= 0 and avoids a libm call; through i64, whose
    // saturating conversion is one instruction and a select, not usize's dozen.
    let k = (s as i64 as usize).min(nk - 2);
    (k, (s - k as f64).clamp(0.0, 1.0))
}

/// Unused values in front of and behind the phase-blocked rail arrays, always zero:
/// the first slot of the first block in memory and the last slot of block `n - 1`
/// read one of them as a neighbour. A whole vector of them, so that blocks start on a
/// cache line.
pub(super) const GUARD: usize = LANES;

/// First storage slot of phase block `p` of `n` whose rail parts are `sp` long: block
/// 0 comes last in memory (after blocks `1..n`), so that the one slot past it, which
/// the last slot of block `n - 1` reads as its right neighbour, is the trailing guard
/// (see [`Track`] on why the padding then needs no clearing).
#[inline(always)]
pub(super) fn block_start(p: usize, n: usize, sp: usize) -> usize {
    // Not `(p + n - 1) % n`: an integer division in front of every loop.
    GUARD + (if p == 0 { n - 1 } else { p - 1 }) * 2 * sp
}
