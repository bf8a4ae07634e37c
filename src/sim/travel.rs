//! [`Simulation`]'s travel along the line: the leading wheelset's position, the speed
//! and the axles' rotation, the endless track's window that moves with the wheelsets
//! by whole sleeper spans, and what is fixed in line coordinates on it (the hanging
//! sleepers). The values kept (`Motion`, `Window`) are in `motion.rs`.

use super::motion::Motion;
use super::simulation::{Simulation, TrackState};
use super::vehicle_state::VehicleState;
use super::wheelset::Wheelset;
use crate::error::{Error, Result};
use crate::sim::TrackWindow;

impl Simulation {
    /// Position of the leading wheelset at the current time (m, line coordinates):
    /// `x_0 + V t` at constant speed, the integral of the speed in general
    /// ([`Simulation::set_speed`]).
    #[inline(always)]
    pub fn position(&self) -> f64 {
        let m = &self.motion;
        m.x_ref + m.speed * (self.time() - m.t_ref)
    }

    /// Forward speed (m/s) from now on.
    pub fn speed(&self) -> f64 {
        self.motion.speed
    }

    /// Line coordinate of the track's left end (m): 0 on a fixed track; on an endless
    /// track, where the window begins now.
    pub fn track_origin(&self) -> f64 {
        self.origin
    }

    /// The endless track's window, `None` on a fixed track.
    pub fn window(&self) -> Option<TrackWindow> {
        self.window.map(|w| w.spec)
    }

    /// Axle rotation angle of the axles that roll without slip at the current time
    /// (rad) (2.17): the leading wheelset's, unless its rotation is an input.
    #[inline(always)]
    pub(super) fn rolling_rotation(&self) -> f64 {
        let m = &self.motion;
        m.rotation_ref + m.speed * (self.time() - m.t_ref) / self.scenario.wheel_radius
    }

    /// Axle rotation angle of wheelset `w` at the current time (rad) (2.17).
    #[inline(always)]
    pub(super) fn rotation_of(&self, w: &Wheelset) -> f64 {
        match &w.vehicle {
            VehicleState::External {
                rotation,
                since,
                rates,
                ..
            } => {
                if rates.rotation_given {
                    *rotation + rates.rotation * (self.time() - since)
                } else {
                    *rotation
                        + self.motion.speed * (self.time() - since) / self.scenario.wheel_radius
                }
            }
            _ => self.rolling_rotation(),
        }
    }

    /// Axle rotation angle of the leading wheelset at the current time (rad) (2.17).
    pub fn rotation(&self) -> f64 {
        self.rotation_of(self.lead())
    }

    /// Changes the forward speed to `v` (m/s) from the current time: the position and
    /// the rolling axles integrate the speed held over each step (the master's
    /// zero-order hold). Standstill (`v = 0`) is allowed; a speed at which a fixed
    /// track would end within the current step is refused at the next step
    /// ([`Error::OffTrack`]).
    ///
    /// Errors: `v` not finite or outside 0 to 200 m/s (named `speed`).
    pub fn set_speed(&mut self, v: f64) -> Result<()> {
        crate::limits::check("speed", v)?;
        // -0 is 0.
        let v = v + 0.0;
        if v == self.motion.speed {
            return Ok(());
        }
        let now = self.time();
        let (x, gamma) = (self.position(), self.rolling_rotation());
        let speed = self.motion.speed;
        let radius = self.scenario.wheel_radius;
        for w in self.wheelsets.iter_mut() {
            if let VehicleState::External {
                rotation,
                since,
                rates,
                ..
            } = &mut w.vehicle
            {
                if rates.rotation_given {
                    *rotation += rates.rotation * (now - *since);
                } else {
                    *rotation += speed * (now - *since) / radius;
                }
                *since = now;
            }
        }
        self.motion = Motion {
            x_ref: x,
            t_ref: now,
            speed: v,
            rotation_ref: gamma,
        };
        self.clear_cache();
        Ok(())
    }

    /// Time (s) at which the leading wheelset reaches the end of a fixed discrete
    /// track at the current speed; `None` for the lumped track, an endless track or
    /// at standstill.
    pub fn time_at_track_end(&self) -> Option<f64> {
        let v = self.motion.speed;
        match &self.track {
            TrackState::Discrete(t) if v > 0.0 && self.window.is_none() => {
                let end = t.params().running_length();
                Some(self.time() + (end - (self.position() - self.origin)) / v)
            }
            _ => None,
        }
    }

    /// Moves the endless track's window forward by the whole spans that put the
    /// leading wheelset back within `ahead` of the window's end.
    #[cold]
    #[inline(never)]
    pub(super) fn move_window(&mut self) -> Result<()> {
        let x = self.position();
        let (Some(w), TrackState::Discrete(t)) = (&mut self.window, &mut self.track) else {
            return Ok(());
        };
        let beyond = x - self.origin - w.shift_at;
        let m = ((beyond / w.spacing).floor() as usize + 1).min(t.params().spans - 1);
        t.shift_spans(m)?;
        w.origin_span += m as i64;
        self.origin = w.origin();
        self.place_voids()?;
        self.clear_cache();
        Ok(())
    }

    /// Position along the line (m) of the sleeper of the longest lift of any support
    /// since the start ([`crate::track::Track::longest_lift`]); 0 when none has lifted.
    pub fn longest_lift_position(&self) -> f64 {
        match &self.track {
            TrackState::Discrete(t) => match t.longest_lift() {
                (0.0, _) => 0.0,
                // The sleeper's index along the line times the spacing: the same
                // number for the same sleeper whatever the window's origin.
                (_, i) => {
                    let a = t.params().sleeper_spacing;
                    ((self.origin / a).round() + i as f64) * a
                }
            },
            TrackState::Lumped(_) => 0.0,
        }
    }

    /// Puts the hanging sleepers ([`Scenario::voids`](crate::sim::Scenario::voids)) where
    /// they lie in the track as it is now (an endless track's window moves over them).
    pub(super) fn place_voids(&mut self) -> Result<()> {
        let (Some(v), TrackState::Discrete(t)) = (&self.voids, &mut self.track) else {
            if self.voids.is_some() {
                return Err(Error::Unsupported(
                    "hanging sleepers on the lumped track (it has no sleepers)".into(),
                ));
            }
            return Ok(());
        };
        let p = t.params();
        let gaps = v.gaps(self.origin, p.spans + 1, p.sleeper_spacing)?;
        t.set_sleeper_gaps(&gaps)
    }
}
