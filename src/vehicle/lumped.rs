//! The chapter-2 lumped models (2.27): a wheel per side on the series suspension, and a
//! track mass per rail.

use crate::error::{Result, non_negative, positive};

/// One central-difference step of `m z'' + c z' + k (z - z_ref) = f`, `[m, c, k] = mck`,
/// with the damping velocity centred as in (3.25); returns `z_(j+1)`.
#[inline]
fn sdof_step(mck: [f64; 3], dt: f64, z: f64, z_prev: f64, z_ref: f64, f: f64) -> f64 {
    let [m, c, k] = mck;
    let a = m / (dt * dt);
    let b = c / (2.0 * dt);
    (f - k * (z - z_ref) + a * (2.0 * z - z_prev) + b * z_prev) / (a + b)
}

/// Chapter-2 lumped wheel (2.27), one per side:
/// `m_w z'' + C z' + K (z - z_0) = -W + P`, with `z_0` the static position so that the
/// static contact force is exactly `W` (the suspension preload carries the body).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LumpedWheelParams {
    /// Half-wheelset mass `m_w` (kg).
    pub mass: f64,
    /// Suspension stiffness `K` (N/m): primary and secondary in series.
    pub stiffness: f64,
    /// Suspension damping `C` (N s/m): primary and secondary in series.
    pub damping: f64,
    /// Static wheel load `W` (N).
    pub load: f64,
}

impl LumpedWheelParams {
    /// Checks every parameter.
    pub fn validate(&self) -> Result<()> {
        positive("vehicle.wheel.mass", self.mass, "kg")?;
        non_negative("vehicle.suspension.stiffness", self.stiffness, "N/m")?;
        non_negative("vehicle.suspension.damping", self.damping, "N s/m")?;
        non_negative("vehicle.wheel.load", self.load, "N")?;
        Ok(())
    }
}

/// Two independent lumped wheels (left, right).
#[derive(Debug, Clone)]
pub struct LumpedWheels {
    /// Parameters (same for both sides).
    pub params: LumpedWheelParams,
    dt: f64,
    z: [f64; 2],
    z_prev: [f64; 2],
    z0: [f64; 2],
}

impl LumpedWheels {
    /// Wheels at rest at zero, stepped with `dt` (s).
    pub fn new(params: LumpedWheelParams, dt: f64) -> Result<Self> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        Ok(LumpedWheels {
            params,
            dt,
            z: [0.0; 2],
            z_prev: [0.0; 2],
            z0: [0.0; 2],
        })
    }
    /// Wheel-centre displacements (m).
    pub fn wheel_z(&self) -> [f64; 2] {
        self.z
    }
    /// Static equilibrium at wheel positions `z` (m) with contact force `W`.
    pub fn set_static(&mut self, z: [f64; 2]) {
        self.z = z;
        self.z_prev = z;
        self.z0 = z;
    }
    /// Advances one step under contact forces `p` (N).
    pub fn step(&mut self, p: [f64; 2]) {
        let q = &self.params;
        for i in 0..2 {
            let (z, zp) = (self.z[i], self.z_prev[i]);
            let f = -q.load + p[i];
            self.z[i] = sdof_step(
                [q.mass, q.damping, q.stiffness],
                self.dt,
                z,
                zp,
                self.z0[i],
                f,
            );
            self.z_prev[i] = z;
        }
    }
}

/// Chapter-2 lumped track (2.27): `m_t z'' + C_t z' + K_t z = -P`, one mass per rail.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LumpedTrackParams {
    /// Track mass `m_t` (kg).
    pub mass: f64,
    /// Support stiffness `K_t` (N/m).
    pub stiffness: f64,
    /// Support damping `C_t` (N s/m).
    pub damping: f64,
}

/// Two lumped track masses (left, right rail).
#[derive(Debug, Clone)]
pub struct LumpedTrack {
    /// Parameters.
    pub params: LumpedTrackParams,
    dt: f64,
    z: [f64; 2],
    z_prev: [f64; 2],
}

impl LumpedTrack {
    /// Track at rest, stepped with `dt` (s).
    pub fn new(params: LumpedTrackParams, dt: f64) -> Result<Self> {
        positive("track.lumped.mass", params.mass, "kg")?;
        positive("track.lumped.stiffness", params.stiffness, "N/m")?;
        non_negative("track.lumped.damping", params.damping, "N s/m")?;
        positive("solver.dt", dt, "s")?;
        Ok(LumpedTrack {
            params,
            dt,
            z: [0.0; 2],
            z_prev: [0.0; 2],
        })
    }
    /// Rail displacement (m).
    pub fn rail_z(&self) -> [f64; 2] {
        self.z
    }
    /// Static equilibrium under loads `p` (N).
    pub fn set_static(&mut self, p: [f64; 2]) {
        for i in 0..2 {
            self.z[i] = -p[i] / self.params.stiffness;
        }
        self.z_prev = self.z;
    }
    /// Advances one step under contact forces `p` (N).
    pub fn step(&mut self, p: [f64; 2]) {
        let q = &self.params;
        let dt = self.dt;
        for i in 0..2 {
            let a = q.mass / (dt * dt);
            let b = q.damping / (2.0 * dt);
            let rhs = -p[i] - q.stiffness * self.z[i]
                + a * (2.0 * self.z[i] - self.z_prev[i])
                + b * self.z_prev[i];
            let next = rhs / (a + b);
            self.z_prev[i] = self.z[i];
            self.z[i] = next;
        }
    }
}
