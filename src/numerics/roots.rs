//! Roots and positive points of a function of one variable on an interval: regula falsi
//! (Anderson-Bjorck) for a bracketed sign change, and a golden-section search with a
//! curvature bound for a positive stretch between two non-positive values.

/// Root of `g` in `[lo, hi]` (where `g` changes sign; `glo`, `ghi` its values there)
/// by the Anderson-Bjorck variant of regula falsi (order about 1.7; the end kept
/// twice has its value scaled by `1 - g(c)/g(b)`, or halved as in Illinois when that
/// is not positive), ended when the bracket is 1e-15 wide (in the units of the
/// argument) or after 100 steps. The bracket `[a, b]` may be reversed; `b` is always
/// the newest point.
#[inline(always)]
pub(crate) fn refine_root<G: Fn(f64) -> f64>(g: &G, lo: f64, glo: f64, hi: f64, ghi: f64) -> f64 {
    let (mut a, mut b) = (lo, hi);
    let (mut fa, mut fb) = (glo, ghi);
    for _ in 0..100 {
        if (b - a).abs() <= 1e-15 {
            break;
        }
        let denom = fb - fa;
        let mut c = if denom != 0.0 {
            b - fb * (b - a) / denom
        } else {
            0.5 * (a + b)
        };
        if !(c > a.min(b) && c < a.max(b)) {
            c = 0.5 * (a + b);
        }
        let fc = g(c);
        if fc == 0.0 {
            return c;
        }
        if (fc > 0.0) != (fb > 0.0) {
            // The root lies between b and c: b becomes the kept end.
            (a, fa) = (b, fb);
        } else {
            // a is kept again: scale its value down.
            let m = 1.0 - fc / fb;
            fa *= if m > 0.0 { m } else { 0.5 };
        }
        (b, fb) = (c, fc);
    }
    0.5 * (a + b)
}

/// A point of `[lo, hi]` where `g` is positive, and `g` there, if golden-section search for the
/// maximum of `g` (unimodal there) finds one; `None` once the values found and the
/// curvature bound (`g` rises at most `rise w^2` above the larger end value of an
/// interval `w` wide, plus `rounding` for the rounding of `g`) show that `g` stays
/// non-positive, or the interval is below 1e-13 wide. `glo`, `ghi`: `g` at the ends.
#[inline(always)]
pub(crate) fn positive_point<G: Fn(f64) -> f64>(
    g: &G,
    lo: f64,
    glo: f64,
    hi: f64,
    ghi: f64,
    rise: f64,
    rounding: f64,
) -> Option<(f64, f64)> {
    const INV_PHI: f64 = 0.618_033_988_749_894_8;
    let (mut a, mut b, mut ga, mut gb) = (lo, hi, glo, ghi);
    let mut c = b - INV_PHI * (b - a);
    let mut d = a + INV_PHI * (b - a);
    let (mut gc, mut gd) = (g(c), g(d));
    for _ in 0..200 {
        if gc > 0.0 {
            return Some((c, gc));
        }
        if gd > 0.0 {
            return Some((d, gd));
        }
        let w = (c - a).max(d - c).max(b - d);
        if b - a < 1e-13 || ga.max(gb).max(gc).max(gd) + rise * w * w + rounding <= 0.0 {
            break;
        }
        if gc > gd {
            (b, gb) = (d, gd);
            (d, gd) = (c, gc);
            c = b - INV_PHI * (b - a);
            gc = g(c);
        } else {
            (a, ga) = (c, gc);
            (c, gc) = (d, gd);
            d = a + INV_PHI * (b - a);
            gd = g(d);
        }
    }
    None
}

/// Ends of a positive stretch (a sliver) of `g` between `lo` and `hi`, where `g` is
/// non-positive (`glo`, `ghi`), or `None` when `g` stays non-positive there (see
/// [`positive_point`], whose `rise` and `rounding` these are). Each end is bracketed
/// between the positive point found and the nearer end of the interval.
#[inline(always)]
pub(crate) fn sliver<G: Fn(f64) -> f64>(
    g: &G,
    lo: f64,
    glo: f64,
    hi: f64,
    ghi: f64,
    rise: f64,
    rounding: f64,
) -> Option<(f64, f64)> {
    let (xp, gp) = positive_point(g, lo, glo, hi, ghi, rise, rounding)?;
    Some((
        refine_root(g, lo, glo, xp, gp),
        refine_root(g, xp, gp, hi, ghi),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rounding allowance of the test functions' values.
    const ROUNDING: f64 = 1e-15;

    #[test]
    fn sliver_search_finds_a_narrow_positive_peak() {
        // A peak 1e-12 high and 2e-6 wide at 0.3 that no sample grid would catch.
        // |g''| = 2: g rises at most w^2 / 4 above the chord of an interval w wide.
        let rise = 0.25;
        let peak = |x: f64| 1e-12 - (x - 0.3) * (x - 0.3);
        let (xp, gp) =
            positive_point(&peak, 0.0, peak(0.0), 1.0, peak(1.0), rise, ROUNDING).unwrap();
        assert!(peak(xp) > 0.0 && gp == peak(xp));
        let below = |x: f64| -1e-12 - (x - 0.3) * (x - 0.3);
        assert_eq!(
            positive_point(&below, 0.0, below(0.0), 1.0, below(1.0), rise, ROUNDING),
            None
        );
        // Both ends of the sliver, the peak near either end of the interval.
        let half = 1e-6;
        for (lo, hi) in [(0.0, 1.0), (0.25, 0.31), (0.29, 0.9)] {
            let (r0, r1) = sliver(&peak, lo, peak(lo), hi, peak(hi), rise, ROUNDING).unwrap();
            assert!((r0 - (0.3 - half)).abs() < 1e-9, "[{lo}, {hi}]: {r0}");
            assert!((r1 - (0.3 + half)).abs() < 1e-9, "[{lo}, {hi}]: {r1}");
        }
        assert_eq!(
            sliver(&below, 0.0, below(0.0), 1.0, below(1.0), rise, ROUNDING),
            None
        );
        // A gap: g positive at both ends, below zero over 2e-6 around 0.3; searched
        // for as a sliver of -g.
        let dip = |x: f64| -peak(x);
        let (r0, r1) =
            sliver(&|x| -dip(x), 0.0, -dip(0.0), 1.0, -dip(1.0), rise, ROUNDING).unwrap();
        assert!((r0 - (0.3 - half)).abs() < 1e-9 && (r1 - (0.3 + half)).abs() < 1e-9);
        // A maximum well below zero is dismissed by the curvature bound in a few
        // evaluations instead of a search down to 1e-13.
        let count = std::cell::Cell::new(0);
        let deep = |x: f64| {
            count.set(count.get() + 1);
            -1e-6 - (x - 0.3) * (x - 0.3)
        };
        assert_eq!(
            positive_point(&deep, 0.29, deep(0.29), 0.32, deep(0.32), rise, ROUNDING),
            None
        );
        assert!(count.get() < 12, "{} evaluations", count.get());
    }
}
