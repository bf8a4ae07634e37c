//! The state vector of a simulation: everything that determines the continuation, so
//! that a saved run continues bit for bit (FMU states).

use super::accelerations::Accelerations;
use super::clock::ForceExtremes;
use super::inputs::InputRates;
use super::motion::Motion;
use super::simulation::{Simulation, TrackState};
use super::sites::Site;
use super::vehicle_state::VehicleState;
use crate::error::{Error, Result, num, out_of_range};
use crate::limits::MIN_DT_FRACTION;

/// Values of the clock at the head of a state vector: step (s), `t0` (s), steps since
/// `t0`, steps since the start.
const CLOCK: usize = 4;

impl Simulation {
    /// Everything that determines the continuation: the clock (step (s), `t0` (s),
    /// steps since `t0`, steps since the start), the force extremes of every wheelset
    /// (`[max left, max right, min left, min right]` (N)) with its contact forces of
    /// the step before and its accelerations' history and extremes
    /// ([`super::Accelerations`]), the sites' extremes, the
    /// track's state, then each wheelset's vehicle's (the roll-plane vehicle's step
    /// and displacements, or the external wheels' inputs: `z` `[left, right]` (m), the
    /// axle angle (rad) and the time (s) it was given at), the motion (position (m)
    /// and time (s) of the speed's last change, the speed (m/s), the rolling axles'
    /// angle then (rad)) and the endless track's window (its first node, in whole
    /// sleeper spans; 0 on a fixed track), then the half-car bogie's state when it
    /// carries the wheelsets (its step and displacements at `t_j` and `t_(j-1)`; a
    /// wheelset on it has none of its own). [`Simulation::set_state_vector`] restores
    /// it exactly.
    ///
    /// Errors: a lumped track or lumped wheels ([`Error::Unsupported`]); only the
    /// discrete track with the roll-plane vehicle, constant loads or external wheels
    /// has a state vector.
    pub fn state_vector(&self) -> Result<Vec<f64>> {
        let c = &self.clock;
        let mut v = vec![c.dt, c.t0, c.k as f64, self.steps as f64];
        for w in self.wheelsets.iter() {
            v.extend(w.extremes.to_array());
            v.extend(w.latest().contact.map(|c| c.force));
            v.extend(w.accelerations.to_array());
        }
        for site in &self.sites {
            v.extend(site.extremes());
        }
        match &self.track {
            TrackState::Discrete(t) => v.extend(t.state_vector()),
            TrackState::Lumped(_) => return Err(Self::no_state()),
        }
        for w in self.wheelsets.iter() {
            v.extend(Self::vehicle_state(&w.vehicle)?);
        }
        v.extend(self.motion.to_array());
        v.push(self.window.map_or(0.0, |w| w.origin_span as f64));
        if let Some(b) = &self.carrier {
            v.extend(b.state_vector());
        }
        Ok(v)
    }

    /// One wheelset's vehicle's part of [`Simulation::state_vector`].
    fn vehicle_state(vehicle: &VehicleState) -> Result<Vec<f64>> {
        Ok(match vehicle {
            VehicleState::RollPlane(r) => r.state_vector(),
            VehicleState::ConstantLoad(_) | VehicleState::OnBogie { .. } => Vec::new(),
            VehicleState::External {
                wheel_z,
                rotation,
                since,
                rates,
            } => {
                let mut v = vec![wheel_z[0], wheel_z[1], *rotation, *since];
                v.extend(rates.to_array());
                v
            }
            VehicleState::AxleBox(link) => link.state_vector(),
            VehicleState::LumpedWheels(_) => return Err(Self::no_state()),
        })
    }

    fn no_state() -> Error {
        Error::Unsupported(
            "state vector of a lumped model (only the discrete track with the roll-plane \
             vehicle or constant loads has one)"
                .into(),
        )
    }

    /// Restores a state written by [`Simulation::state_vector`] of a simulation built
    /// from the same scenario. Refused: a wrong length, a step outside what
    /// [`Simulation::new`] accepts, a clock or step count that is not a whole number
    /// below 2^53, and a state beyond the health bounds ([`Simulation::check_health`]),
    /// which then stays in the simulation: rebuild it.
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        if let (Some(&dt), TrackState::Discrete(_)) = (v.first(), &self.track) {
            let c = self.critical_step;
            if !(dt >= MIN_DT_FRACTION * c && dt <= c) {
                return Err(out_of_range(
                    "state: step",
                    dt,
                    format!("{} s <= dt <= {} s", num(MIN_DT_FRACTION * c), num(c)),
                ));
            }
        }
        let count = crate::limits::is_count;
        if v.len() >= CLOCK && !(v[1].is_finite() && v[1] >= 0.0 && count(v[2]) && count(v[3])) {
            return Err(out_of_range(
                "state: clock",
                v[1],
                "t0 finite and >= 0 s, step counts whole numbers in [0, 2^53)",
            ));
        }
        let nt = match &self.track {
            TrackState::Discrete(t) => t.state_len(),
            TrackState::Lumped(_) => return Err(Self::no_state()),
        };
        let nv = Self::vehicle_state(&self.wheelsets.lead().vehicle)?.len();
        let nw = self.wheelsets.len();
        let per_wheelset = ForceExtremes::LEN + 2 + Accelerations::LEN;
        let extremes_end = CLOCK + per_wheelset * self.wheelsets.len();
        let head = extremes_end + Site::STATE_LEN * self.sites.len();
        let nb = self.carrier.as_ref().map_or(0, |b| b.state_vector().len());
        let total = head + nt + nw * nv + Motion::LEN + 1 + nb;
        if v.len() != total {
            return Err(out_of_range(
                "simulation state length",
                v.len() as f64,
                format!("{total} values for this scenario"),
            ));
        }
        let forces = v[CLOCK..extremes_end].chunks_exact(per_wheelset);
        if let Some(&x) = forces
            .flat_map(|x| &x[ForceExtremes::LEN..ForceExtremes::LEN + 2])
            .find(|x| !x.is_finite())
        {
            return Err(out_of_range(
                "state: contact force of the step before",
                x,
                "finite",
            ));
        }
        let tail = &v[total - nb - Motion::LEN - 1..total - nb];
        let origin_span = tail[Motion::LEN];
        if !(tail.iter().all(|x| x.is_finite())
            && tail[2] >= 0.0
            && origin_span.fract() == 0.0
            && origin_span.abs() < 2f64.powi(53))
        {
            return Err(out_of_range(
                "state: motion",
                tail[2],
                "position, time, speed >= 0 m/s, rotation finite; window origin a whole number",
            ));
        }
        if let TrackState::Discrete(t) = &mut self.track {
            t.set_state_vector(&v[head..head + nt])?;
        }
        let vehicles = v[head + nt..head + nt + nw * nv].chunks_exact(nv.max(1));
        for (w, e) in self.wheelsets.iter_mut().zip(vehicles) {
            match &mut w.vehicle {
                VehicleState::RollPlane(r) => r.set_state_vector(e)?,
                VehicleState::AxleBox(link) => link.set_state_vector(e)?,
                VehicleState::External {
                    wheel_z,
                    rotation,
                    since,
                    rates,
                } => {
                    if let Some(&x) = e.iter().find(|x| !x.is_finite()) {
                        return Err(out_of_range("state: wheel inputs", x, "finite"));
                    }
                    *wheel_z = [e[0], e[1]];
                    *rotation = e[2];
                    *since = e[3];
                    *rates = InputRates::from_slice(&e[4..4 + InputRates::LEN]);
                }
                _ => {}
            }
        }
        if let Some(b) = &mut self.carrier {
            b.set_state_vector(&v[total - nb..])?;
        }
        self.motion = Motion::from_slice(tail);
        if let Some(w) = &mut self.window {
            w.origin_span = origin_span as i64;
            self.origin = w.origin();
            self.place_voids()?;
        }
        let c = &mut self.clock;
        (c.dt, c.t0, c.k) = (v[0], v[1], v[2] as u64);
        self.steps = v[3] as u64;
        let extremes = v[CLOCK..extremes_end].chunks_exact(per_wheelset);
        for (w, x) in self.wheelsets.iter_mut().zip(extremes) {
            w.extremes = ForceExtremes::from_slice(&x[..ForceExtremes::LEN]);
            for (c, &f) in w.latest.contact.iter_mut().zip(&x[ForceExtremes::LEN..]) {
                c.force = f;
            }
            let a = &x[ForceExtremes::LEN + 2..];
            if let Some(&bad) = a.iter().find(|x| !x.is_finite()) {
                return Err(out_of_range("state: accelerations", bad, "finite"));
            }
            w.accelerations = Accelerations::from_slice(a);
        }
        if let TrackState::Discrete(t) = &self.track {
            let stored = v[extremes_end..head].chunks_exact(Site::STATE_LEN);
            for (site, x) in self.sites.iter_mut().zip(stored) {
                site.restore(t, self.origin, x);
            }
        }
        self.clear_cache();
        self.check_health()
    }
}
