//! Observation points fixed in track coordinates: what the track feels there at every
//! step (rail displacement, bending moment and shear force; at the nearest sleeper the
//! rail seat force, the seat's displacement and the ballast force, and how long the
//! pad or the ballast has let go, for both rails),
//! with the extremes since the start, so that a coarse output never hides a passing
//! peak.

use crate::error::{Result, out_of_range};
use crate::limits::MAX_SITES;
use crate::track::Track;

/// The quantities recorded at a site for each rail, in the order of [`SiteValues`]:
/// rail displacement (m), rail bending moment (N m), rail shear force (N), rail seat
/// force (N), seat displacement (m), ballast force (N), how long the rail has been
/// lifted off the pad and the seat off the ballast without a break (s) (see
/// [`crate::track::RailResponse`] and [`crate::track::SupportResponse`]), and the
/// rail's and the seat's vertical acceleration (m/s^2, up): the central second
/// difference of their displacements at the track's steps, at one step before the
/// current time (summed twice it gives the displacements back exactly; the run starts
/// at rest).
pub const SITE_QUANTITIES: [&str; 10] = [
    "rail.z",
    "rail.bending_moment",
    "rail.shear_force",
    "seat.force",
    "seat.z",
    "ballast.force",
    "seat.lifted",
    "ballast.lifted",
    "rail.acceleration",
    "seat.acceleration",
];

/// The displacements whose accelerations a site keeps: rail (0) and seat (4).
const MOVING: [usize; 2] = [0, 4];

/// Number of [`SITE_QUANTITIES`].
const NQ: usize = SITE_QUANTITIES.len();

/// The values of [`SITE_QUANTITIES`] on the left (0) and right (1) rail.
pub type SiteValues = [[f64; NQ]; 2];

/// One observation point: its position and what the track feels there.
#[derive(Debug, Clone, PartialEq)]
pub struct Site {
    position: f64,
    /// The rail's and the seat's displacements ([`MOVING`]) of each rail at the last
    /// two steps, the latest first (m).
    before: [[[f64; 2]; 2]; 2],
    /// The steps (s) from the latest of them to now and from the one before to the
    /// latest: equal but where the step changed.
    steps: [f64; 2],
    now: SiteValues,
    max: SiteValues,
    min: SiteValues,
}

impl Site {
    /// Position along the track (m).
    pub fn position(&self) -> f64 {
        self.position
    }
    /// The values at the current time `t_j`.
    pub fn now(&self) -> &SiteValues {
        &self.now
    }
    /// The largest values since the start (the static state included).
    pub fn max(&self) -> &SiteValues {
        &self.max
    }
    /// The smallest values since the start.
    pub fn min(&self) -> &SiteValues {
        &self.min
    }

    /// Whether `x` (m, line coordinates) lies inside `track`, whose node 0 lies at
    /// `origin` (m).
    /// Not on the window's end nodes: an endless window holds its ends at rest (the
    /// rail there jumps to 0 as the window moves on), so a site there reads the track
    /// at rest already, a span before its sleeper leaves the window.
    fn on_track(track: &Track, origin: f64, x: f64) -> bool {
        let x = x - origin;
        x > 0.0 && x < track.params().length()
    }

    /// What `track`, whose node 0 lies at `origin` (m), feels at `x` (m, line
    /// coordinates) now; `None` outside the track (the track at rest there): an endless
    /// track's window has not reached the site yet, or has left it behind.
    fn read(track: &Track, origin: f64, x: f64) -> Option<SiteValues> {
        if !Self::on_track(track, origin, x) {
            return None;
        }
        let x = x - origin;
        Some([0, 1].map(|rail| {
            let r = track.rail_response(rail, x);
            let s = track.support_response(rail, x);
            [
                r.displacement,
                r.bending_moment,
                r.shear_force,
                s.rail_seat_force,
                s.seat_displacement,
                s.ballast_force,
                s.pad_lifted,
                s.ballast_lifted,
                0.0,
                0.0,
            ]
        }))
    }

    /// The accelerations of [`MOVING`] in `now` from the history and its steps. Off
    /// an endless track's window the site reads the track at rest: no acceleration,
    /// and a history at rest, as the track that enters the window is.
    fn accelerate(&mut self, on_track: bool) {
        if !on_track {
            self.before = [[[0.0; 2]; 2]; 2];
            for rail in 0..2 {
                self.now[rail][NQ - 2] = 0.0;
                self.now[rail][NQ - 1] = 0.0;
            }
            return;
        }
        let [h1, h2] = self.steps;
        let k = 1.0 / (h1 * h1);
        for rail in 0..2 {
            for (m, &q) in MOVING.iter().enumerate() {
                let [a, b] = self.before[rail][m];
                let z = self.now[rail][q];
                // Where the step changed: the slopes' difference over the mean step.
                self.now[rail][NQ - 2 + m] = if h1 != h2 {
                    2.0 * ((z - a) / h1 - (a - b) / h2) / (h1 + h2)
                } else {
                    (z - 2.0 * a + b) * k
                };
            }
        }
    }

    /// Reads what the track feels at the site now, with the accelerations.
    fn read_now(&mut self, track: &Track, origin: f64) {
        let values = Self::read(track, origin, self.position);
        self.now = values.unwrap_or([[0.0; NQ]; 2]);
        self.accelerate(values.is_some());
    }

    /// Reads the track now and takes the values into the extremes.
    pub(crate) fn record(&mut self, track: &Track, origin: f64) {
        for rail in 0..2 {
            for (m, &q) in MOVING.iter().enumerate() {
                self.before[rail][m] = [self.now[rail][q], self.before[rail][m][0]];
            }
        }
        self.steps = [track.dt(), self.steps[0]];
        self.read_now(track, origin);
        for rail in 0..2 {
            for q in 0..NQ {
                let x = self.now[rail][q];
                self.max[rail][q] = self.max[rail][q].max(x);
                self.min[rail][q] = self.min[rail][q].min(x);
            }
        }
    }

    /// Values of the extremes and of the accelerations' history in the order state
    /// vectors store them.
    pub(crate) fn extremes(&self) -> impl Iterator<Item = f64> + '_ {
        let before = self.before.iter().flatten().flatten().chain(&self.steps);
        self.max
            .iter()
            .chain(&self.min)
            .flatten()
            .chain(before)
            .copied()
    }

    /// Number of values [`Site::extremes`] yields.
    pub(crate) const STATE_LEN: usize = 4 * NQ + 10;

    /// Restores the extremes and history from [`Site::extremes`] and reads the track
    /// now.
    pub(crate) fn restore(&mut self, track: &Track, origin: f64, v: &[f64]) {
        let before = self
            .before
            .iter_mut()
            .flatten()
            .flatten()
            .chain(&mut self.steps);
        let slots = self
            .max
            .iter_mut()
            .chain(&mut self.min)
            .flatten()
            .chain(before);
        for (slot, &x) in slots.zip(v) {
            *slot = x;
        }
        self.read_now(track, origin);
    }
}

/// The observation points at `positions` (m, line coordinates) on `track`, whose node 0
/// lies at `origin` (m), their extremes started at the track's current state.
///
/// Errors: more than [`MAX_SITES`] points; a point outside a fixed track (`endless`
/// false), or not finite.
pub(crate) fn sites(
    track: &Track,
    origin: f64,
    endless: bool,
    positions: &[f64],
) -> Result<Vec<Site>> {
    if positions.len() > MAX_SITES {
        return Err(out_of_range(
            "sites",
            positions.len() as f64,
            format!("at most {MAX_SITES} observation points"),
        ));
    }
    let len = track.params().length();
    positions
        .iter()
        .enumerate()
        .map(|(j, &x)| {
            let name = format!("site[{}].position", j + 1);
            if endless {
                crate::error::finite(&name, x, "m")?;
            } else if !(x > 0.0 && x < len) {
                return Err(out_of_range(
                    &name,
                    x,
                    format!(
                        "0 m < {name} < {len} m (on the fixed track; an endless track, \
                         track.window.ahead > 0, takes any position)"
                    ),
                ));
            }
            let now = Site::read(track, origin, x).unwrap_or([[0.0; NQ]; 2]);
            // At rest before the start: the history holds the static state.
            let at_rest = |rail: usize| MOVING.map(|q| [now[rail][q]; 2]);
            Ok(Site {
                position: x,
                before: [at_rest(0), at_rest(1)],
                steps: [track.dt(); 2],
                now,
                max: now,
                min: now,
            })
        })
        .collect()
}
