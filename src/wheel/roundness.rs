//! A measured wheel out-of-roundness: the running surface's radius deviation against
//! the angle around the wheel (a measured polygonal wheel, a wheel with a tread
//! defect), on top of the nominal circle and its flats.

use crate::error::{Result, out_of_range};
use crate::numerics::Table;
use std::f64::consts::TAU;

/// Largest radius deviation a table may hold (m): beyond a few millimetres a wheel is
/// no longer a wheel with a measured out-of-roundness.
pub const MAX_RADIUS_DEVIATION: f64 = 0.005;

/// The radius deviation `r(beta)` (m, positive where the wheel is larger than nominal)
/// against the wheel angle `beta` (rad): the angle of a point of the running surface
/// from the downward vertical when the axle rotation is 0, positive ahead, as the flats'
/// angles are measured (the point at `beta` touches the rail when the axle rotation is
/// `beta`, `docs/MODEL.md`, "Measured irregularities"). Points joined by straight
/// lines, once round the wheel: the last point joins the first one a turn later.
///
/// The contact sees it where the wheel touches the rail, as a change of the overlap:
/// the deviation must vary slowly over the contact patch (wavelengths above about ten
/// patch lengths, 0.1 m); shorter defects are flats.
#[derive(Debug, Clone, PartialEq)]
pub struct OutOfRoundness {
    table: Table,
}

impl OutOfRoundness {
    /// From a table of wheel angle (rad, `0 <= beta < 2 pi`) against radius deviation
    /// (m, at most [`MAX_RADIUS_DEVIATION`] either way); `name` names the table in
    /// errors.
    pub fn new(table: Table, name: &str) -> Result<Self> {
        let (first, last) = table.range();
        if !(first >= 0.0 && last < TAU) {
            let bad = if first < 0.0 { first } else { last };
            return Err(out_of_range(
                &format!("{name} (wheel angle)"),
                bad,
                "0 rad <= angle < 2 pi rad",
            ));
        }
        let (_, r) = table.points();
        if let Some(&bad) = r.iter().find(|r| r.abs() > MAX_RADIUS_DEVIATION) {
            return Err(out_of_range(
                &format!("{name} (radius deviation)"),
                bad,
                format!("-{MAX_RADIUS_DEVIATION} m <= deviation <= {MAX_RADIUS_DEVIATION} m"),
            ));
        }
        Ok(OutOfRoundness { table })
    }

    /// Checks that the contact can follow the table on a wheel of `radius` (m): the
    /// deviation against the distance along the tread (`radius` times the angle, once
    /// round the wheel, the last point joining the first), held to `limits` (slope,
    /// change of slope per metre, corner length; `source` says where they come from,
    /// [`crate::numerics::Table::check_followable`]). `name` names the table.
    pub fn check_followable(
        &self,
        radius: f64,
        limits: (f64, f64, f64),
        source: &str,
        name: &str,
    ) -> Result<()> {
        self.table.check_followable(
            &format!("{name} (radius deviation along the tread, wheel radius {radius} m)"),
            radius,
            Some(TAU),
            limits,
            source,
        )
    }

    /// The wrap-around segment, from the last point to the first a turn later: its
    /// start angle, the deviation there, and its slope; `beta` in `[0, 2 pi)`.
    #[inline]
    fn wrap(&self) -> (f64, f64, f64) {
        let (b, r) = self.table.points();
        let (b0, r0, b1, r1) = (b[b.len() - 1], r[r.len() - 1], b[0] + TAU, r[0]);
        (b0, r0, (r1 - r0) / (b1 - b0))
    }

    /// The radius deviation (m) at wheel angle `beta` (rad, any; taken round the wheel).
    #[inline]
    pub fn at(&self, beta: f64) -> f64 {
        let beta = beta.rem_euclid(TAU);
        let (first, last) = self.table.range();
        if beta >= first && beta <= last {
            return self.table.at(beta);
        }
        // Between the last point and the first, a turn on.
        let (b0, r0, slope) = self.wrap();
        let beta = if beta < first { beta + TAU } else { beta };
        r0 + slope * (beta - b0)
    }

    /// `dr/dbeta` (m/rad) at wheel angle `beta` (rad).
    #[inline]
    pub fn slope_at(&self, beta: f64) -> f64 {
        let beta = beta.rem_euclid(TAU);
        let (first, last) = self.table.range();
        if beta >= first && beta <= last {
            self.table.slope_at(beta)
        } else {
            self.wrap().2
        }
    }
}
