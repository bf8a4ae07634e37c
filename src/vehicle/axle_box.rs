//! The axle-box interface of the roll-plane vehicle: the thesis' six-degree-of-freedom
//! model (3.1-3.3) cut at the primary suspension into
//!
//! * [`WheelsetBody`], the wheelset (bounce `z_w` and roll `phi_w`, mass `m_w`, roll
//!   inertia `J_w`, gravity), driven by the two contact forces from below and the two
//!   primary (axle-box) forces from above; it rides with the track, on the track's
//!   step, so the stiff contact (about 1.5e9 N/m against 1,120 kg) never crosses a
//!   co-simulation interface;
//! * [`SprungBogie`], the bodies above it (bolster bounce and roll, two side frames),
//!   driven by the axle boxes' displacements and velocities through the primary
//!   suspension, whose forces it returns.
//!
//! Joined at every step of the same size they are the monolithic model; exchanged every
//! communication step of a bogie model (about 1 ms) the interface is the soft primary
//! suspension (27 Hz against the side frame), which an explicit exchange carries.
//! Signs: displacements up, roll positive raising the right side, the primary force
//! positive pressing the wheelset down (`docs/MODEL.md`).

use super::RollPlaneParams;
use crate::error::{Result, out_of_range, positive};
use crate::limits::{BODY_DISPLACEMENT_LIMIT, within};

/// The wheelset of the roll-plane vehicle on its own: bounce and roll under the contact
/// forces `P` `[left, right]` (N, up on the wheels) and the axle-box forces `F`
/// `[left, right]` (N, down on the axle boxes), both at half the primary spacing `L_w /
/// 2` from the centre, and gravity; advanced by central differences (no damping of its
/// own: the primary dampers are the bogie side's).
#[derive(Debug, Clone)]
pub struct WheelsetBody {
    mass: f64,
    inertia: f64,
    /// Half the primary spacing `L_w / 2` (m): axle boxes and contact points.
    half: f64,
    gravity: f64,
    dt: f64,
    /// `[z_w, phi_w]` at `t_j` (m, rad).
    d: [f64; 2],
    /// `[z_w, phi_w]` at `t_(j-1)`.
    d_prev: [f64; 2],
}

impl WheelsetBody {
    /// The wheelset of `p` (its mass, roll inertia, primary spacing and gravity), at
    /// rest at zero, stepped with `dt` (s).
    ///
    /// Errors: the wheelset's mass or roll inertia, the primary spacing or gravity
    /// outside its physical range ([`crate::limits::check`]); `dt` not positive.
    pub fn new(p: &RollPlaneParams, dt: f64) -> Result<WheelsetBody> {
        for (name, x) in [
            ("vehicle.wheelset.mass", p.wheelset_mass),
            ("vehicle.wheelset.inertia", p.wheelset_inertia),
            ("vehicle.primary.spacing", p.primary_spacing),
            ("gravity", p.gravity),
        ] {
            crate::limits::check(name, x)?;
        }
        positive("solver.dt", dt, "s")?;
        Ok(WheelsetBody {
            mass: p.wheelset_mass,
            inertia: p.wheelset_inertia,
            half: 0.5 * p.primary_spacing,
            gravity: p.gravity,
            dt,
            d: [0.0; 2],
            d_prev: [0.0; 2],
        })
    }

    /// The wheel-centre (and axle-box) displacements `[left, right]` (m): `z_w -+ L_w/2
    /// phi_w`.
    #[inline(always)]
    pub fn wheel_z(&self) -> [f64; 2] {
        let [z, phi] = self.d;
        [z - self.half * phi, z + self.half * phi]
    }

    /// The axle boxes' velocities `[left, right]` (m/s), backward differences over the
    /// last step.
    pub fn box_velocity(&self) -> [f64; 2] {
        let v = [
            (self.d[0] - self.d_prev[0]) / self.dt,
            (self.d[1] - self.d_prev[1]) / self.dt,
        ];
        [v[0] - self.half * v[1], v[0] + self.half * v[1]]
    }

    /// Static axle-box loads `[left, right]` (N) that hold the wheelset on the static
    /// contact forces `p` (N): `p - m_w g / 2` each, the roll moments balanced.
    pub fn static_box_force(&self, p: [f64; 2]) -> [f64; 2] {
        let w = 0.5 * self.mass * self.gravity;
        [p[0] - w, p[1] - w]
    }

    /// Puts the wheelset at rest with its wheel centres at `z_wheel` `[left, right]` (m).
    pub fn set_static(&mut self, z_wheel: [f64; 2]) {
        self.d = [
            0.5 * (z_wheel[0] + z_wheel[1]),
            (z_wheel[1] - z_wheel[0]) / (2.0 * self.half),
        ];
        self.d_prev = self.d;
    }

    /// Advances one step from `t_j` under the contact forces `p` and the axle-box forces
    /// `f` held over it (N).
    #[inline(always)]
    pub fn step(&mut self, p: [f64; 2], f: [f64; 2]) {
        let up = [p[0] - f[0], p[1] - f[1]];
        let force = up[0] + up[1] - self.mass * self.gravity;
        let moment = self.half * (up[1] - up[0]);
        let h2 = self.dt * self.dt;
        let next = [
            2.0 * self.d[0] - self.d_prev[0] + h2 * force / self.mass,
            2.0 * self.d[1] - self.d_prev[1] + h2 * moment / self.inertia,
        ];
        self.d_prev = self.d;
        self.d = next;
    }

    /// Changes the step to `dt` (s), keeping the displacements and the backward-difference
    /// velocities.
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        positive("solver.dt", dt, "s")?;
        let r = dt / self.dt;
        for i in 0..2 {
            self.d_prev[i] = self.d[i] - (self.d[i] - self.d_prev[i]) * r;
        }
        self.dt = dt;
        Ok(())
    }

    /// `[dt, z_w, phi_w, z_w prev, phi_w prev]`.
    pub fn state_vector(&self) -> Vec<f64> {
        vec![
            self.dt,
            self.d[0],
            self.d[1],
            self.d_prev[0],
            self.d_prev[1],
        ]
    }

    /// Restores [`WheelsetBody::state_vector`].
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        if v.len() != 5 {
            return Err(out_of_range(
                "wheelset state length",
                v.len() as f64,
                "5 values",
            ));
        }
        if v[0] != self.dt {
            self.change_dt(v[0])?;
        }
        self.d = [v[1], v[2]];
        self.d_prev = [v[3], v[4]];
        Ok(())
    }

    /// `[z_w, phi_w]` beyond [`BODY_DISPLACEMENT_LIMIT`], as in the roll-plane vehicle.
    pub fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        [
            ("wheelset.z (m)", self.d[0]),
            ("wheelset.roll (rad)", self.d[1]),
        ]
        .into_iter()
        .find(|(_, x)| !within(*x, BODY_DISPLACEMENT_LIMIT))
        .map(|(n, x)| (n, x, BODY_DISPLACEMENT_LIMIT))
    }
}

/// The side frames' inertia at the axle boxes, as the track side carries it over a
/// communication step ([`PrimaryLink`]): the acceleration of a side frame at an axle box
/// per newton of primary force there, and at the other wheelset's axle box on the same
/// side frame. For a rigid side frame of mass `m` and pitch inertia `J` over two axle
/// boxes at `+-l` from its centre (`l` half the wheelbase) these are the entries of its
/// mobility `G M^-1 G^T`: `1/m + l^2/J` and `1/m - l^2/J`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SideFrameInertia {
    /// Acceleration at an axle box per newton of primary force there (1/kg).
    pub direct: f64,
    /// Acceleration at the other wheelset's axle box on the same side frame per newton
    /// at this one (1/kg); 0 for side frames over one wheelset.
    pub cross: f64,
}

impl SideFrameInertia {
    /// Nothing above the axle boxes that the track moves on: the suspension's upper
    /// ends go on at the velocity they came in with over a communication step (the
    /// two-axle wagon, whose car body there is slow beside the exchange).
    pub const NONE: SideFrameInertia = SideFrameInertia {
        direct: 0.0,
        cross: 0.0,
    };

    /// A side frame of mass `mass` (kg) over one wheelset's axle box, bounce only (the
    /// roll-plane vehicle, (3.1)).
    pub fn single(mass: f64) -> SideFrameInertia {
        SideFrameInertia {
            direct: 1.0 / mass,
            cross: 0.0,
        }
    }

    /// Advances a side frame at an axle box by one track step `dt` (s) from `(z, v)` (m,
    /// m/s; the velocity at the half step behind), the axle box at `box_z` (m) moving at
    /// `box_v` (m/s), under the primary spring `k1` (N/m) and damper `c1` (N s/m), the
    /// held acceleration from above `free` (m/s^2) and the primary force at the other
    /// wheelset's box on the same side frame `partner` (N): symplectic Euler with the
    /// damper implicit in the side frame's velocity, so any damping stays stable.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn advance(
        &self,
        (k1, c1, dt): (f64, f64, f64),
        free: f64,
        (box_z, box_v): (f64, f64),
        partner: f64,
        z: &mut f64,
        v: &mut f64,
    ) {
        let drive = free + self.direct * (k1 * (box_z - *z) + c1 * box_v) + self.cross * partner;
        *v = (*v + dt * drive) / (1.0 + dt * self.direct * c1);
        *z += dt * *v;
    }

    /// A side frame of mass `mass` (kg) and pitch inertia `pitch_inertia` (kg m^2) over
    /// two wheelsets `wheelbase` (m) apart, bouncing and pitching (the half-car bogie).
    pub fn pitching(mass: f64, pitch_inertia: f64, wheelbase: f64) -> SideFrameInertia {
        let l2 = 0.25 * wheelbase * wheelbase;
        SideFrameInertia {
            direct: 1.0 / mass + l2 / pitch_inertia,
            cross: 1.0 / mass - l2 / pitch_inertia,
        }
    }
}

/// The wheelset with its primary suspension, as the track side carries it when the
/// bogie above is a co-simulation partner: the side frames' displacements and velocities
/// `[left, right]` come in at each communication point, and at every step the primary
/// forces `F = K_1 (z_box - z_sf) + C_1 (v_box - v_sf)` (pressing the wheelset down) load
/// the wheelset; their mean over the steps since the last input goes out to the bogie.
///
/// Over the communication step the side frames move on from the input as bodies of
/// their own inertia ([`SideFrameInertia`]) under these primary forces and the static
/// load from above (secondary suspension and gravity, held), not at a constant
/// velocity: the side frame answers the primary damper within `m / C_1` (about 2 ms),
/// as fast as a bogie model's communication step, so a side frame that ignored the
/// wheelset's motion within the step was the largest error of the exchange. Measured
/// against the monolithic model (`examples/axle_box_masters.rs`, reference flat, 1 ms):
/// the peak within 0.1 % when the master hands the bogie this step's mean force
/// (Gauss-Seidel, track first; -0.62 % at a constant velocity), within 0.7 % when it
/// hands it on one step later (Jacobi; -1.6 %), and stable at 2 ms under both.
#[derive(Debug, Clone)]
pub struct PrimaryLink {
    body: WheelsetBody,
    stiffness: f64,
    damping: f64,
    inertia: SideFrameInertia,
    /// Side frames at the last input `[left, right]` (m) and their velocities (m/s).
    frame_z: [f64; 2],
    frame_v: [f64; 2],
    /// The side frames now, moved on from the input (m, m/s; the velocity at the half
    /// step behind).
    now_z: [f64; 2],
    now_v: [f64; 2],
    /// Acceleration of the side frames at the axle boxes from everything but the
    /// primary forces (m/s^2): the static load from above, held.
    free: [f64; 2],
    /// Primary forces at the other wheelset's axle boxes on the same side frames (N),
    /// of its last step ([`PrimaryLink::set_partner_force`]).
    partner: [f64; 2],
    /// The primary forces of the last step (N).
    last: [f64; 2],
    /// Steps since the last input.
    steps: u64,
    /// Sum of the primary forces over those steps (N).
    force_sum: [f64; 2],
}

impl PrimaryLink {
    /// The wheelset and primary suspension of `p`, stepped with `dt` (s), under side
    /// frames of inertia `inertia`.
    ///
    /// Errors: as [`WheelsetBody::new`], and the primary stiffness or damping outside
    /// its physical range; an inertia that is not a positive finite direct mobility
    /// with a cross mobility of smaller magnitude.
    pub fn new(p: &RollPlaneParams, dt: f64, inertia: SideFrameInertia) -> Result<PrimaryLink> {
        crate::limits::check("vehicle.primary.stiffness", p.primary_stiffness)?;
        crate::limits::check("vehicle.primary.damping", p.primary_damping)?;
        check_inertia(inertia)?;
        Ok(PrimaryLink {
            body: WheelsetBody::new(p, dt)?,
            stiffness: p.primary_stiffness,
            damping: p.primary_damping,
            inertia,
            frame_z: [0.0; 2],
            frame_v: [0.0; 2],
            now_z: [0.0; 2],
            now_v: [0.0; 2],
            free: [0.0; 2],
            partner: [0.0; 2],
            last: [0.0; 2],
            steps: 0,
            force_sum: [0.0; 2],
        })
    }

    /// The wheelset.
    pub fn body(&self) -> &WheelsetBody {
        &self.body
    }

    /// The primary stiffness `K_1` (N/m).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// The primary damping `C_1` (N s/m).
    pub fn damping(&self) -> f64 {
        self.damping
    }

    /// The side frames' inertia.
    pub fn inertia(&self) -> SideFrameInertia {
        self.inertia
    }

    /// Carries side frames of `inertia` from now on, the held load from above kept (the
    /// static forces it balances): what TrackContact fitted of its partner's
    /// ([`super::PartnerFit`], `vehicle.sideframe.source = auto`).
    ///
    /// Errors: an inertia [`PrimaryLink::new`] refuses, or [`SideFrameInertia::NONE`]
    /// for side frames that had one (or the reverse).
    pub fn set_inertia(&mut self, inertia: SideFrameInertia) -> Result<()> {
        check_inertia(inertia)?;
        let (old, new) = (
            self.inertia.direct + self.inertia.cross,
            inertia.direct + inertia.cross,
        );
        if (old == 0.0) != (new == 0.0) {
            return Err(out_of_range(
                "side frame mobility",
                inertia.direct,
                "side frames where the track carried them, none where it carried none",
            ));
        }
        if old != 0.0 {
            self.free = self.free.map(|a| a * new / old);
        }
        self.inertia = inertia;
        Ok(())
    }

    /// Static equilibrium: the wheels at `z_wheel` (m) on the static contact forces `p`
    /// (N), the side frames where the primary springs carry the axle-box loads, the
    /// load from above balancing them (the other wheelset on a shared side frame
    /// carrying the same).
    pub fn set_static(&mut self, z_wheel: [f64; 2], p: [f64; 2]) {
        self.body.set_static(z_wheel);
        let f = self.body.static_box_force(p);
        let zb = self.body.wheel_z();
        self.frame_z = [0, 1].map(|i| zb[i] - f[i] / self.stiffness);
        self.frame_v = [0.0; 2];
        self.now_z = self.frame_z;
        self.now_v = [0.0; 2];
        let m = self.inertia;
        self.free = f.map(|fi| -(m.direct + m.cross) * fi);
        self.partner = f;
        self.last = f;
        self.force_sum = [0.0; 2];
        self.steps = 0;
    }

    /// The side frames' displacements and velocities `[left, right]` (m, m/s) last set.
    pub fn side_frames(&self) -> ([f64; 2], [f64; 2]) {
        (self.frame_z, self.frame_v)
    }

    /// Takes the side frames' displacements `z` (m) and velocities `v` (m/s) at the
    /// current time; the mean primary force restarts.
    pub fn set_side_frames(&mut self, z: [f64; 2], v: [f64; 2]) {
        self.frame_z = z;
        self.frame_v = v;
        self.now_z = z;
        self.now_v = v;
        self.steps = 0;
        self.force_sum = [0.0; 2];
    }

    /// The primary forces `[left, right]` (N) of the last step (at the static state,
    /// the static ones).
    pub fn last_force(&self) -> [f64; 2] {
        self.last
    }

    /// The primary forces `[left, right]` (N) at the other wheelset's axle boxes on the
    /// same side frames, which move these ones through the side frames' pitch.
    pub fn set_partner_force(&mut self, f: [f64; 2]) {
        self.partner = f;
    }

    /// The primary forces `[left, right]` (N) at the current state: the wheelset's and
    /// the side frames' displacements and velocities now.
    pub fn force_now(&self) -> [f64; 2] {
        let (zb, vb) = (self.body.wheel_z(), self.body.box_velocity());
        [0, 1].map(|i| {
            self.stiffness * (zb[i] - self.now_z[i]) + self.damping * (vb[i] - self.now_v[i])
        })
    }

    /// The primary forces averaged over the steps since the last input (N); those of
    /// the current state before the first step.
    pub fn mean_force(&self) -> [f64; 2] {
        if self.steps == 0 {
            return self.force_now();
        }
        let n = self.steps as f64;
        [self.force_sum[0] / n, self.force_sum[1] / n]
    }

    /// Advances one step under the contact forces `p` (N): the wheelset under them and
    /// the primary forces, then the side frames under the primary forces (the damper
    /// implicit in the side frame's velocity, so any damping stays stable) and the held
    /// load from above.
    #[inline(always)]
    pub fn step(&mut self, p: [f64; 2]) {
        let f = self.force_now();
        let (zb, vb) = (self.body.wheel_z(), self.body.box_velocity());
        self.body.step(p, f);
        let link = (self.stiffness, self.damping, self.body.dt);
        for i in 0..2 {
            self.inertia.advance(
                link,
                self.free[i],
                (zb[i], vb[i]),
                self.partner[i],
                &mut self.now_z[i],
                &mut self.now_v[i],
            );
        }
        self.last = f;
        self.force_sum[0] += f[0];
        self.force_sum[1] += f[1];
        self.steps += 1;
    }

    /// Changes the step (s), as [`WheelsetBody::change_dt`]; the side frames go on
    /// from where they are.
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        self.body.change_dt(dt)
    }

    /// Values of [`PrimaryLink::state_vector`].
    const STATE_LEN: usize = 24;

    /// The wheelset's state (5), then the side frames at the input (z, v), the steps
    /// and force sums since the last input, the side frames now (z, v), the load from
    /// above, the partner's and the last primary forces, the side frames' mobilities
    /// (direct, cross; [`PrimaryLink::set_inertia`] may change them): 24 values.
    pub fn state_vector(&self) -> Vec<f64> {
        let mut v = self.body.state_vector();
        v.extend(self.frame_z);
        v.extend(self.frame_v);
        v.push(self.steps as f64);
        v.extend(self.force_sum);
        v.extend(self.now_z);
        v.extend(self.now_v);
        v.extend(self.free);
        v.extend(self.partner);
        v.extend(self.last);
        v.extend([self.inertia.direct, self.inertia.cross]);
        v
    }

    /// Restores [`PrimaryLink::state_vector`].
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        if v.len() != Self::STATE_LEN || !crate::limits::is_count(v[9]) {
            return Err(out_of_range(
                "primary suspension state",
                v.len() as f64,
                format!("{} values, a whole step count", Self::STATE_LEN),
            ));
        }
        let inertia = SideFrameInertia {
            direct: v[22],
            cross: v[23],
        };
        check_inertia(inertia)?;
        self.body.set_state_vector(&v[..5])?;
        let pair = |i: usize| [v[i], v[i + 1]];
        self.frame_z = pair(5);
        self.frame_v = pair(7);
        self.steps = v[9] as u64;
        self.force_sum = pair(10);
        self.now_z = pair(12);
        self.now_v = pair(14);
        self.free = pair(16);
        self.partner = pair(18);
        self.last = pair(20);
        self.inertia = inertia;
        Ok(())
    }
}

/// Refuses an inertia that is not [`SideFrameInertia::NONE`] or a positive finite direct
/// mobility with a cross mobility of smaller magnitude.
fn check_inertia(inertia: SideFrameInertia) -> Result<()> {
    if !(inertia == SideFrameInertia::NONE
        || inertia.direct.is_finite()
            && inertia.direct > 0.0
            && inertia.cross.abs() < inertia.direct)
    {
        return Err(out_of_range(
            "side frame mobility",
            inertia.direct,
            "a positive direct mobility 1/m + l^2/J above the cross mobility's magnitude, \
             or none",
        ));
    }
    Ok(())
}
