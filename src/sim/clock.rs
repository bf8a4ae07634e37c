//! What both co-simulation units share: the model clock, the number of steps that
//! take it to the master's time, and the contact-force extremes.
//!
//! [`super::Simulation`] steps on a fixed grid and ends each communication step at the
//! grid point nearest the master's time; [`super::VehicleUnit`] cuts each
//! communication step into equal substeps and follows the master's clock exactly, up
//! to a remainder below [`MIN_STEP_FRACTION`] of its base step that it carries over.

use crate::limits::MIN_STEP_FRACTION;

/// How a unit follows the master's clock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stepping {
    /// The fixed grid `t_k = t0 + k dt`: a communication step ends at the grid point
    /// nearest the master's time, so the step never changes (the explicit track is not
    /// stable under every sequence of step changes near its limit) and the model time
    /// stays within half a step of the master's.
    Grid,
    /// Equal substeps of at most the base step that end at the master's time; a
    /// remainder below [`MIN_STEP_FRACTION`] of the base step is carried over.
    Substeps,
}

/// The model clock of a co-simulation unit: `t = t0 + k dt` (s), `dt` the step in use
/// since `t0`, `k` the steps taken since. Counting steps rather than summing them keeps
/// the time on the grid of the step in use without rounding drift.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Clock {
    /// Step in use (s).
    pub(crate) dt: f64,
    /// Time at which the step in use began (s).
    pub(crate) t0: f64,
    /// Steps taken since `t0`.
    pub(crate) k: u64,
    /// The step the unit was built with (s): the longest substep.
    pub(crate) base: f64,
    /// Communication time not yet stepped (s) ([`Stepping::Substeps`] only; always 0 on
    /// the grid).
    pub(crate) carried: f64,
    /// How the clock follows the master's.
    pub(crate) stepping: Stepping,
}

/// A communication step to the master's model time `end` (s) that a unit has planned
/// and checked against its work limit before anything moves
/// ([`super::Simulation::plan_to`], [`super::VehicleUnit::plan_to`]). It holds for the
/// state of the unit it was planned in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepPlan {
    pub(crate) end: f64,
    pub(crate) tolerance: f64,
    pub(crate) steps: f64,
}

impl StepPlan {
    /// The master's model time the step ends at (s), from the start of the run.
    pub fn end(&self) -> f64 {
        self.end
    }
    /// The rounding of the master's clock (s) the plan allows for.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }
    /// Steps of the unit it takes.
    pub fn steps(&self) -> f64 {
        self.steps
    }
}

/// The substeps of one communication step ([`Clock::substeps`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Substeps {
    /// Number of equal steps; 0 when the time is carried over instead.
    pub(crate) n: f64,
    /// The communication step with the time carried from earlier calls (s).
    pub(crate) total: f64,
    /// The new step `total / n` (s) when `n` steps of the step in use miss `total` by
    /// more than the clock tolerance; `None` when the step in use fits.
    pub(crate) dt: Option<f64>,
}

impl Clock {
    /// A clock at `t = 0` with step `dt` (s), which is also the base step.
    pub(crate) fn new(dt: f64, stepping: Stepping) -> Clock {
        Clock {
            dt,
            t0: 0.0,
            k: 0,
            base: dt,
            carried: 0.0,
            stepping,
        }
    }

    /// Model time `t0 + k dt` (s).
    #[inline(always)]
    pub(crate) fn time(&self) -> f64 {
        self.t0 + self.k as f64 * self.dt
    }

    /// Model time after `n` more steps of the step in use (s).
    pub(crate) fn time_after(&self, n: u64) -> f64 {
        self.t0 + (self.k + n) as f64 * self.dt
    }

    /// The master's time as the unit has taken it in (s): the model time and the time
    /// carried over.
    pub(crate) fn reached(&self) -> f64 {
        self.time() + self.carried
    }

    /// One step of the step in use taken.
    #[inline(always)]
    pub(crate) fn tick(&mut self) {
        self.k += 1;
    }

    /// The step changes to `dt` (s) from the current time on.
    pub(crate) fn restart(&mut self, dt: f64) {
        self.t0 = self.time();
        self.k = 0;
        self.dt = dt;
    }

    /// Steps that take the unit to the master's model time `end` (s), `tolerance` (s)
    /// the rounding of the master's clock: on the grid, to the grid point nearest `end`
    /// (`round((end - t0) / dt) - k`, none when that is behind); in substeps,
    /// [`Clock::substeps`] of what `end` is ahead of the time taken in.
    #[inline(always)]
    pub(crate) fn steps_to(&self, end: f64, tolerance: f64) -> f64 {
        match self.stepping {
            Stepping::Grid => {
                let target = ((end - self.t0) / self.dt).round().max(0.0);
                (target - self.k as f64).max(0.0)
            }
            Stepping::Substeps => self.substeps(end - self.reached(), tolerance).n,
        }
    }

    /// The plan of a communication step to the master's model time `end` (s)
    /// ([`Clock::steps_to`]).
    #[inline(always)]
    pub(crate) fn plan_to(&self, end: f64, tolerance: f64) -> StepPlan {
        StepPlan {
            end,
            tolerance,
            steps: self.steps_to(end, tolerance),
        }
    }

    /// The equal substeps of a communication step `h` (s) with the time carried over
    /// from earlier calls, `total = h + carried`: `n = ceil((total - tolerance) / base)`,
    /// at least 1, so a step that is a whole multiple of the base step up to the
    /// clock's rounding `tolerance` (s) takes exactly that many steps; none when
    /// `total` is below [`MIN_STEP_FRACTION`] of the base step (a step that short would
    /// round the velocities away). The step in use is kept when `n` of it are `total`
    /// to within `tolerance`; otherwise the substep is `total / n`.
    pub(crate) fn substeps(&self, h: f64, tolerance: f64) -> Substeps {
        let total = h + self.carried;
        let n = if total < MIN_STEP_FRACTION * self.base {
            0.0
        } else {
            ((total - tolerance) / self.base).ceil().max(1.0)
        };
        let dt = (n > 0.0 && (total - n * self.dt).abs() > tolerance).then(|| total / n);
        Substeps { n, total, dt }
    }
}

/// The largest and smallest contact force per wheel `[left, right]` (N) that has driven
/// a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ForceExtremes {
    /// Largest force per wheel (N).
    pub(crate) max: [f64; 2],
    /// Smallest force per wheel (N).
    pub(crate) min: [f64; 2],
}

impl ForceExtremes {
    /// The extremes of no force at all: finite, so that a state saved before the first
    /// step serialises (`f64::MIN` and `f64::MAX` give way to any force).
    pub(crate) const NONE: ForceExtremes = ForceExtremes {
        max: [f64::MIN; 2],
        min: [f64::MAX; 2],
    };

    /// Values in a state vector.
    pub(crate) const LEN: usize = 4;

    /// Extremes that start at the forces `p` (N).
    pub(crate) fn at(p: [f64; 2]) -> ForceExtremes {
        ForceExtremes { max: p, min: p }
    }

    /// Takes the forces `p` (N) of a step in.
    #[inline(always)]
    pub(crate) fn record(&mut self, p: [f64; 2]) {
        for i in 0..2 {
            self.max[i] = self.max[i].max(p[i]);
            self.min[i] = self.min[i].min(p[i]);
        }
    }

    /// `[max left, max right, min left, min right]`, the order of the state vectors.
    pub(crate) fn to_array(self) -> [f64; 4] {
        let ([a, b], [c, d]) = (self.max, self.min);
        [a, b, c, d]
    }

    /// The inverse of [`ForceExtremes::to_array`], from the first [`ForceExtremes::LEN`]
    /// values of `v`.
    pub(crate) fn from_slice(v: &[f64]) -> ForceExtremes {
        ForceExtremes {
            max: [v[0], v[1]],
            min: [v[2], v[3]],
        }
    }
}
