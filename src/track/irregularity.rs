//! The rail's vertical profile along the line: a measured irregularity (height against
//! position) and a discrete defect of ready shape (a dipped weld or joint), fixed in
//! line coordinates (an endless track's window reads it where it is).

use crate::error::{Result, out_of_range};
use crate::numerics::Table;
use std::f64::consts::TAU;

/// Largest height a measured rail profile or a defect may have either way (m).
pub const MAX_RAIL_IRREGULARITY: f64 = 0.01;

/// Shortest dipped weld or joint (m): the contact sees the rail at the wheel's point,
/// so shorter features are the contact patch's business.
pub const MIN_DEFECT_LENGTH: f64 = 0.1;

/// The steepest slope (rad) and sharpest change of slope (1/m) of the steepest dipped
/// weld the parameters allow ([`MAX_RAIL_IRREGULARITY`] deep over
/// [`MIN_DEFECT_LENGTH`]): a cosine of depth `D` over `L` rises at most `pi D / L`
/// (0.314) and bends at most `2 pi^2 D / L^2` (19.7 1/m); and the length over which a
/// corner's turn is judged, `L / 20` (5 mm: that weld sampled every 5 mm turns by at
/// most 0.0987 at a point). A measured table (rail profile, wheel out-of-roundness along
/// the tread) is held to the same ([`Table::check_followable`]), so that the contact
/// follows every table it accepts as it follows that weld: a 10 mm rise over 32 mm with
/// sharp corners (turns of 0.31 between long pieces) passed the first two limits and
/// reached 2.2 to 2.6 MN at 35 to 100 m/s where the weld peaks at 1.41 MN (issue 38).
pub const FOLLOWABLE: (f64, f64, f64) = (
    std::f64::consts::PI * MAX_RAIL_IRREGULARITY / MIN_DEFECT_LENGTH,
    2.0 * std::f64::consts::PI * std::f64::consts::PI * MAX_RAIL_IRREGULARITY
        / (MIN_DEFECT_LENGTH * MIN_DEFECT_LENGTH),
    MIN_DEFECT_LENGTH / 20.0,
);

/// Where [`FOLLOWABLE`] comes from, for error messages.
pub const FOLLOWABLE_SOURCE: &str = "the steepest dipped weld allowed, 0.01 m deep over 0.1 m: rail.defect.depth and \
     rail.defect.length";

/// A dipped weld or joint: the rail head dips by `depth` over `length`, centred at
/// `position`, in the shape of one cosine wave, `-depth (1 + cos(2 pi (x - x_0) /
/// length)) / 2` for `|x - x_0| < length / 2`: the usual idealisation of a dipped weld
/// or joint, smooth at its ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RailDefect {
    /// Centre along the line (m).
    pub position: f64,
    /// Length (m), 0.1 to 10.
    pub length: f64,
    /// Depth (m, positive down), 0 to [`MAX_RAIL_IRREGULARITY`].
    pub depth: f64,
}

impl RailDefect {
    /// Checks the fields; `name` prefixes their names (`rail.defect`).
    pub fn validate(&self, name: &str) -> Result<()> {
        crate::error::finite(&format!("{name}.position"), self.position, "m")?;
        if !(MIN_DEFECT_LENGTH..=10.0).contains(&self.length) {
            return Err(out_of_range(
                &format!("{name}.length"),
                self.length,
                "0.1 m <= length <= 10 m (the contact sees the rail at the wheel's point: \
                 shorter defects are the patch's business)",
            ));
        }
        if !(0.0..=MAX_RAIL_IRREGULARITY).contains(&self.depth) {
            return Err(out_of_range(
                &format!("{name}.depth"),
                self.depth,
                format!("0 m <= depth <= {MAX_RAIL_IRREGULARITY} m"),
            ));
        }
        Ok(())
    }

    /// Height (m, up) and slope at `x` (m).
    #[inline]
    fn at(&self, x: f64) -> (f64, f64) {
        let u = (x - self.position) / self.length;
        if u.abs() >= 0.5 {
            return (0.0, 0.0);
        }
        let (s, c) = (TAU * u).sin_cos();
        (
            -0.5 * self.depth * (1.0 + c),
            0.5 * self.depth * TAU / self.length * s,
        )
    }
}

/// One rail's vertical profile along the line: the height of its running surface above
/// the ideal line (m, up), a measured table (position (m) against height (m), the end
/// heights beyond its ends) plus a discrete defect plus a drawn random profile. It enters the contact where the
/// wheel touches the rail, as a change of the overlap (a raised rail presses into the
/// wheel); the track's dynamics are those of the ideal rail loaded there.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RailProfile {
    /// The measured height.
    pub measured: Option<std::sync::Arc<Table>>,
    /// A dipped weld or joint.
    pub defect: Option<RailDefect>,
    /// A profile drawn from a standard spectrum, with the rail's short-wave roughness
    /// ([`super::ProfileSpec`], `crate::contact::RoughnessSpectrum`).
    pub random: Option<std::sync::Arc<super::RandomProfile>>,
}

impl RailProfile {
    /// Checks a measured table's heights (at most [`MAX_RAIL_IRREGULARITY`] either way)
    /// and its steepness ([`FOLLOWABLE`]); `name` names it in errors.
    pub fn check_measured(table: &Table, name: &str) -> Result<()> {
        let (_, h) = table.points();
        if let Some(&bad) = h.iter().find(|h| h.abs() > MAX_RAIL_IRREGULARITY) {
            return Err(out_of_range(
                &format!("{name} (height)"),
                bad,
                format!("-{MAX_RAIL_IRREGULARITY} m <= height <= {MAX_RAIL_IRREGULARITY} m"),
            ));
        }
        table.check_followable(
            &format!("{name} (height against position)"),
            1.0,
            None,
            FOLLOWABLE,
            FOLLOWABLE_SOURCE,
        )
    }

    /// Whether the rail has any irregularity.
    pub fn is_some(&self) -> bool {
        self.measured.is_some() || self.defect.is_some() || self.random.is_some()
    }

    /// The height (m, up) and its slope `dh/dx` at `x` (m, line coordinates).
    #[inline]
    pub fn at(&self, x: f64) -> (f64, f64) {
        let (mut h, mut s) = self.defect.map_or((0.0, 0.0), |d| d.at(x));
        if let Some(t) = &self.measured {
            h += t.at(x);
            s += t.slope_at(x);
        }
        if let Some(r) = &self.random {
            let (dh, ds) = r.at(x);
            h += dh;
            s += ds;
        }
        (h, s)
    }
}
