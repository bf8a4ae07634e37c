//! A two-axle freight wagon (docs/MODEL.md, "The two-axle wagon"): the car body on two
//! wheelsets without bogies, as the common two-axle European wagons run, one suspension
//! stage (the axle-box springs and dampers) between them. Seven degrees of freedom
//! `d = {z_c, theta_c, phi_c, z_w1, phi_w1, z_w2, phi_w2}`: the car body in bounce, pitch
//! (positive raising the front, the leading wheelset's end) and roll (positive raising
//! the right side), each wheelset in bounce and roll. A spring and a damper join the car
//! body above each axle box, at `x = +- a / 2` along the track (the wheelbase `a`, the
//! leading wheelset at `+a / 2`) and `y = -+ L_w / 2` across it, to the axle box there.
//! Gravity acts on every body, the contact forces on the four wheels.
//!
//! Parameters (a stated derivation, [`TwoAxleParams::table_4_4`]): the thesis' wheelsets
//! and primary suspension per axle box (table 4.4), the car body the wagon's
//! ([`super::WagonParams::table_4_4`]: a uniform box 14 m long, 2.8 m wide, 2.5 m high)
//! carrying half its load, twice the thesis' car-body share per wheelset (40.3 t), on a
//! 9 m wheelbase: 21.3 t per axle, a loaded two-axle wagon of UIC axle-load class C.

use super::linear_body::{LinearBody, LinearVehicle, SprungLinearBody};
use super::rail_vehicle::{Axles, Bodies, CarrierModel, RailVehicle, SprungVehicle};
use super::{ExchangeLimits, MAX_AXLES, RollPlaneParams, SideFrameInertia};
use crate::error::Result;
use crate::limits::check;
use nalgebra::{SMatrix, SVector};

/// Degrees of freedom of the two-axle wagon.
pub const TWO_AXLE_DOFS: usize = 7;
/// Degrees of freedom above the suspension: the car body's three.
const CARBODY_DOFS: usize = 3;
/// The two-axle wagon's wheelbase (m): from a short wagon's to a long one's (a 40 ft
/// container wagon's, about 14 m, the most UIC 505-1's gauge allows a two-axle wagon of
/// this width).
pub const WHEELBASE_RANGE: (f64, f64) = (4.0, 14.0);
type Vector = SVector<f64, TWO_AXLE_DOFS>;
type Matrix = SMatrix<f64, TWO_AXLE_DOFS, TWO_AXLE_DOFS>;

/// Parameters of the two-axle wagon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoAxleParams {
    /// Car-body mass (kg).
    pub carbody_mass: f64,
    /// Car-body pitch inertia about its centre (kg m^2).
    pub carbody_pitch_inertia: f64,
    /// Car-body roll inertia about its centre line (kg m^2).
    pub carbody_roll_inertia: f64,
    /// Mass of one wheelset (kg).
    pub wheelset_mass: f64,
    /// Roll inertia of one wheelset (kg m^2).
    pub wheelset_inertia: f64,
    /// Suspension stiffness per axle box `K_1` (N/m).
    pub stiffness: f64,
    /// Suspension damping per axle box `C_1` (N s/m).
    pub damping: f64,
    /// Lateral distance between the axle boxes (and the contact points) `L_w` (m).
    pub spacing: f64,
    /// Wheelbase `a` (m): the distance between the two wheelsets.
    pub wheelbase: f64,
    /// Gravitational acceleration `g` (m/s^2).
    pub gravity: f64,
}

impl TwoAxleParams {
    /// The two-axle wagon of the roll-plane vehicle `p` (table 4.4): its wheelsets and
    /// primary suspension at each axle box, the car body twice its car-body share per
    /// wheelset with the inertias `(pitch, roll)` (kg m^2) of the four-axle wagon's car
    /// body halved (the same box, half the mass), on the wheelbase `wheelbase` (m).
    pub fn table_4_4(p: &RollPlaneParams, inertias: (f64, f64), wheelbase: f64) -> TwoAxleParams {
        TwoAxleParams {
            carbody_mass: 2.0 * p.carbody_mass,
            carbody_pitch_inertia: 0.5 * inertias.0,
            carbody_roll_inertia: 0.5 * inertias.1,
            wheelset_mass: p.wheelset_mass,
            wheelset_inertia: p.wheelset_inertia,
            stiffness: p.primary_stiffness,
            damping: p.primary_damping,
            spacing: p.primary_spacing,
            wheelbase,
            gravity: p.gravity,
        }
    }

    /// Where wheelset `i` (0 leading) lies from the car body's centre (m): `+-a / 2`.
    fn axle_x(&self, i: usize) -> f64 {
        if i == 0 {
            0.5 * self.wheelbase
        } else {
            -0.5 * self.wheelbase
        }
    }

    /// Where side `s` (0 left) lies from the centre line (m): `-+ L_w / 2`.
    fn side_y(&self, s: usize) -> f64 {
        if s == 0 {
            -0.5 * self.spacing
        } else {
            0.5 * self.spacing
        }
    }

    /// The elongation coefficients of the spring at axle box `(i, s)`: the car body
    /// above it minus the axle box.
    fn link(&self, i: usize, s: usize) -> Vector {
        let (x, y) = (self.axle_x(i), self.side_y(s));
        let mut a = Vector::zeros();
        a[0] = 1.0;
        a[1] = x;
        a[2] = y;
        a[3 + 2 * i] = -1.0;
        a[4 + 2 * i] = -y;
        a
    }

    fn assemble(&self, constant: f64) -> Matrix {
        let mut m = Matrix::zeros();
        for i in 0..2 {
            for s in 0..2 {
                let a = self.link(i, s);
                m += a * a.transpose() * constant;
            }
        }
        m
    }

    /// Static contact force on each of the four wheels (N): a quarter of the weight.
    pub fn static_wheel_load(&self) -> f64 {
        0.25 * self.gravity * (self.carbody_mass + 2.0 * self.wheelset_mass)
    }
}

impl LinearVehicle<TWO_AXLE_DOFS, CARBODY_DOFS> for TwoAxleParams {
    const WHAT: &'static str = "two-axle wagon";
    const DOF_NAMES: [&'static str; TWO_AXLE_DOFS] = [
        "carbody.z (m)",
        "carbody.pitch (rad)",
        "carbody.roll (rad)",
        "wheelset.z (m)",
        "wheelset.roll (rad)",
        "wheelset[2].z (m)",
        "wheelset[2].roll (rad)",
    ];
    const WHEELSETS: usize = 2;
    const SPRUNG: [usize; CARBODY_DOFS] = [0, 1, 2];

    /// Every parameter in its range, named as the FMU variables: the car body's mass as
    /// its share per wheelset (`vehicle.carbody_mass`), its inertias as the four-axle
    /// wagon's car body of twice them, the wheelbase as `wheelset[2].offset`.
    fn validate(&self) -> Result<()> {
        check("vehicle.carbody_mass", 0.5 * self.carbody_mass)?;
        check(
            "vehicle.carbody.pitch_inertia",
            2.0 * self.carbody_pitch_inertia,
        )?;
        check(
            "vehicle.carbody.roll_inertia",
            2.0 * self.carbody_roll_inertia,
        )?;
        check("vehicle.wheelset.mass", self.wheelset_mass)?;
        check("vehicle.wheelset.inertia", self.wheelset_inertia)?;
        check("vehicle.primary.stiffness", self.stiffness)?;
        check("vehicle.primary.damping", self.damping)?;
        check("vehicle.primary.spacing", self.spacing)?;
        let (lo, hi) = WHEELBASE_RANGE;
        if !(self.wheelbase >= lo && self.wheelbase <= hi) {
            return Err(crate::error::out_of_range(
                "wheelset[2].offset",
                self.wheelbase,
                format!("{lo} m <= wheelset[2].offset <= {hi} m (the two-axle wagon's wheelbase)"),
            ));
        }
        check("gravity", self.gravity)?;
        crate::error::positive("vehicle.carbody_mass", self.carbody_mass, "kg")?;
        Ok(())
    }
    fn mass_diagonal(&self) -> Vector {
        let (mw, jw) = (self.wheelset_mass, self.wheelset_inertia);
        Vector::from_column_slice(&[
            self.carbody_mass,
            self.carbody_pitch_inertia,
            self.carbody_roll_inertia,
            mw,
            jw,
            mw,
            jw,
        ])
    }
    fn stiffness_matrix(&self) -> Matrix {
        self.assemble(self.stiffness)
    }
    fn damping_matrix(&self) -> Matrix {
        self.assemble(self.damping)
    }
    /// The car body has no suspension above its axle boxes but the axle boxes' own.
    fn above_primary(&self) -> (Matrix, Matrix) {
        (Matrix::zeros(), Matrix::zeros())
    }
    fn gravity_force(&self) -> Vector {
        let g = self.gravity;
        let mut f = -self.mass_diagonal() * g;
        // Inertias carry no weight.
        for i in [1, 2, 4, 6] {
            f[i] = 0.0;
        }
        f
    }
    fn contact_force(&self, p: &Axles) -> Vector {
        let hw = 0.5 * self.spacing;
        let mut f = Vector::zeros();
        for (i, [l, r]) in p.iter().take(2).enumerate() {
            f[3 + 2 * i] = l + r;
            f[4 + 2 * i] = hw * (r - l);
        }
        f
    }
    fn wheels_of(&self, d: &[f64]) -> Axles {
        let mut a = [[0.0; 2]; MAX_AXLES];
        for (i, ai) in a.iter_mut().take(2).enumerate() {
            *ai = [0, 1].map(|s| d[3 + 2 * i] + self.side_y(s) * d[4 + 2 * i]);
        }
        a
    }
    fn frames_at_boxes(&self, d: &[f64]) -> Axles {
        let mut a = [[0.0; 2]; MAX_AXLES];
        for (i, ai) in a.iter_mut().take(2).enumerate() {
            let x = self.axle_x(i);
            *ai = [0, 1].map(|s| d[0] + x * d[1] + self.side_y(s) * d[2]);
        }
        a
    }
    fn add_primary_forces(&self, f: &Axles, g: &mut SVector<f64, CARBODY_DOFS>) {
        for (i, fi) in f.iter().take(2).enumerate() {
            let x = self.axle_x(i);
            for (s, &fs) in fi.iter().enumerate() {
                g[0] += fs;
                g[1] += x * fs;
                g[2] += self.side_y(s) * fs;
            }
        }
    }
    fn primary(&self) -> (f64, f64) {
        (self.stiffness, self.damping)
    }
    fn static_state(&self, z: &Axles) -> Option<Vector> {
        let hw = 0.5 * self.spacing;
        let mut d = Vector::zeros();
        for (i, [l, r]) in z.iter().take(2).enumerate() {
            d[3 + 2 * i] = 0.5 * (l + r);
            d[4 + 2 * i] = (r - l) / (2.0 * hw);
        }
        let k = self.stiffness_matrix();
        let rhs = self.gravity_force().fixed_rows::<3>(0)
            - k.fixed_view::<3, 4>(0, 3) * d.fixed_rows::<4>(3);
        let body = k.fixed_view::<3, 3>(0, 0).into_owned().lu().solve(&rhs)?;
        d.fixed_rows_mut::<3>(0).copy_from(&body);
        d.iter().all(|x| x.is_finite()).then_some(d)
    }
    fn static_contact_forces(&self, d: &Vector) -> Axles {
        let r = self.stiffness_matrix() * d - self.gravity_force();
        let hw = 0.5 * self.spacing;
        let mut p = [[0.0; 2]; MAX_AXLES];
        for (i, pi) in p.iter_mut().take(2).enumerate() {
            let (f, m) = (r[3 + 2 * i], r[4 + 2 * i]);
            *pi = [0.5 * (f - m / hw), 0.5 * (f + m / hw)];
        }
        p
    }
    fn bodies(&self, d: &[f64]) -> Bodies {
        let mut b = Bodies {
            carbody: [d[0], d[1], d[2]],
            ..Bodies::default()
        };
        for i in 0..2 {
            b.wheelset[i] = [d[3 + 2 * i], d[4 + 2 * i]];
        }
        b
    }
    /// The car body above the axle boxes exchanges with wheelsets whose suspensions'
    /// upper ends the track moves on at the velocity they came in with
    /// ([`TwoAxleParams::above_axle_boxes`]).
    fn exchange_limits(
        &self,
        body: &SprungLinearBody<Self, TWO_AXLE_DOFS, CARBODY_DOFS>,
        z: &Axles,
        base: f64,
        support: f64,
    ) -> Result<ExchangeLimits> {
        super::exchange::linear_limits(
            body,
            &self.wheelset(),
            self.above_axle_boxes(),
            z,
            base,
            support,
        )
    }
}

impl TwoAxleParams {
    /// What TrackContact carries above each axle box at the axle-box interface: nothing
    /// ([`SideFrameInertia::NONE`]). The suspension's upper ends are the car body,
    /// whose modes on the suspension lie below 5 Hz: over a communication step of 1 ms
    /// they move on at the velocity they came in with. Measured in
    /// docs/VALIDATION.md (the exchange's stable steps with and without the car body's
    /// effective mass at each axle box).
    pub fn above_axle_boxes(&self) -> SideFrameInertia {
        SideFrameInertia::NONE
    }

    /// The car body's effective mass at an axle box (kg): the inverse of its mobility
    /// there, `1 / (1/m + x^2/J_pitch + y^2/J_roll)`.
    pub fn effective_mass(&self) -> f64 {
        let (x, y) = (0.5 * self.wheelbase, 0.5 * self.spacing);
        1.0 / (1.0 / self.carbody_mass
            + x * x / self.carbody_pitch_inertia
            + y * y / self.carbody_roll_inertia)
    }

    /// The wheelset and its suspension, in the roll-plane vehicle's parameters, as the
    /// track side carries them ([`super::PrimaryLink`] uses no more).
    pub fn wheelset(&self) -> RollPlaneParams {
        RollPlaneParams::wheelset_on_primary(
            self.wheelset_mass,
            self.wheelset_inertia,
            (self.stiffness, self.damping, self.spacing),
            self.gravity,
        )
    }
}

/// The two-axle wagon in time under the four contact forces.
pub type TwoAxleWagon = LinearBody<TwoAxleParams, TWO_AXLE_DOFS, CARBODY_DOFS>;
/// The two-axle wagon's car body above its axle boxes, under the four suspension forces.
pub type SprungTwoAxleWagon = SprungLinearBody<TwoAxleParams, TWO_AXLE_DOFS, CARBODY_DOFS>;

impl CarrierModel for TwoAxleParams {
    fn wheelsets(&self) -> usize {
        2
    }
    fn offsets(&self) -> Vec<(f64, &'static str)> {
        vec![(self.wheelbase, "the wheelbase")]
    }
    fn name(&self) -> &'static str {
        "the two-axle wagon (vehicle.model = two_axle)"
    }
    fn validate(&self) -> Result<()> {
        LinearVehicle::validate(self)
    }
    fn critical_time_step(&self) -> f64 {
        LinearVehicle::critical_time_step(self)
    }
    fn default_dt(&self) -> f64 {
        LinearVehicle::default_dt(self)
    }
    fn static_wheel_load(&self) -> f64 {
        TwoAxleParams::static_wheel_load(self)
    }
    fn stiffnesses(&self) -> Vec<(&'static str, f64)> {
        vec![("vehicle.primary.stiffness", self.stiffness)]
    }
    fn whole(&self, dt: f64) -> Result<Box<dyn RailVehicle>> {
        Ok(Box::new(TwoAxleWagon::new(*self, dt)?))
    }
    fn sprung(&self, dt: f64) -> Result<Box<dyn SprungVehicle>> {
        Ok(Box::new(SprungTwoAxleWagon::new(*self, dt)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vehicle::rail_vehicle::RailVehicle;

    fn wagon() -> TwoAxleParams {
        let p = crate::sim::Scenario::table_4_4();
        let crate::sim::VehicleSpec::RollPlane(v) = p.vehicle else {
            panic!("table 4.4 has the roll-plane vehicle")
        };
        TwoAxleParams::table_4_4(&v, (1_358_110.0, 94_642.0), 9.0)
    }

    /// The frequencies against the general (non-symmetric) eigenvalues of `M^-1 K`
    /// by the real Schur form, an algorithm independent of the symmetric one the
    /// vehicle uses.
    #[test]
    fn natural_frequencies_are_the_eigenvalues_of_m_inverse_k() {
        let p = wagon();
        let m = p.mass_diagonal();
        let a = Matrix::from_diagonal(&m.map(|x| 1.0 / x)) * p.stiffness_matrix();
        let mut general: Vec<f64> = a
            .schur()
            .eigenvalues()
            .expect("real eigenvalues")
            .iter()
            .copied()
            .collect();
        general.sort_by(f64::total_cmp);
        let top = general[TWO_AXLE_DOFS - 1];
        let w = p.natural_frequencies();
        // Three rigid modes (the wheelsets free of the rails: bounce, pitch, roll).
        for (a, &l) in w.iter().zip(&general) {
            assert!((a * a - l).abs() <= 1e-9 * top, "{a} against {l}");
            if l > 1e-6 * top {
                assert!(
                    (a / l.sqrt() - 1.0).abs() <= 1e-6,
                    "{a} against {}",
                    l.sqrt()
                );
            }
        }
        assert_eq!(general.iter().filter(|&&l| l.abs() < 1e-9 * top).count(), 3);
        // With the wheelsets held (on rigid rails) the car body bounces, pitches and
        // rolls on its four springs, decoupled by symmetry: sqrt(4 K_1 / m),
        // sqrt(4 K_1 (a/2)^2 / J_pitch), sqrt(4 K_1 (L_w/2)^2 / J_roll).
        let k = p.stiffness_matrix().fixed_view::<3, 3>(0, 0).into_owned();
        let held = crate::numerics::natural_frequencies(&m.fixed_rows::<3>(0).into_owned(), &k);
        let (x, y) = (0.5 * p.wheelbase, 0.5 * p.spacing);
        let mut closed = [
            (4.0 * p.stiffness / p.carbody_mass).sqrt(),
            (4.0 * p.stiffness * x * x / p.carbody_pitch_inertia).sqrt(),
            (4.0 * p.stiffness * y * y / p.carbody_roll_inertia).sqrt(),
        ];
        let hz = closed.map(|w| w / std::f64::consts::TAU);
        closed.sort_by(f64::total_cmp);
        for (a, b) in held.iter().zip(closed) {
            assert!((a / b - 1.0).abs() < 1e-12, "{a} against {b}");
        }
        // The car body bounces at 4.04 Hz, pitches at 4.43 Hz and rolls at 2.98 Hz.
        for (f, want) in hz.iter().zip([4.04, 4.43, 2.98]) {
            assert!((f - want).abs() < 0.005, "{hz:?}");
        }
    }

    #[test]
    fn each_wheel_carries_its_share_of_the_weight() {
        let p = wagon();
        let mut body = TwoAxleWagon::new(p, 1e-4).unwrap();
        let z = [[-1e-3, -1.2e-3], [-0.9e-3, -1.1e-3], [0.0; 2], [0.0; 2]];
        let forces = RailVehicle::set_static(&mut body, &z).unwrap();
        let weight = p.gravity * (p.carbody_mass + 2.0 * p.wheelset_mass);
        let total: f64 = forces[..2].iter().flatten().sum();
        assert!(
            (total / weight - 1.0).abs() < 1e-12,
            "{total} against {weight}"
        );
        // Level wheels: a quarter each.
        let forces = RailVehicle::set_static(&mut body, &[[0.0; 2]; MAX_AXLES]).unwrap();
        for f in forces[..2].iter().flatten() {
            assert!((f / (0.25 * weight) - 1.0).abs() < 1e-12, "{f}");
            assert!((f / p.static_wheel_load() - 1.0).abs() < 1e-12);
        }
        // 104.3 kN: 21.3 t per axle.
        assert!(
            (p.static_wheel_load() - 104_329.35).abs() < 1.0,
            "{}",
            p.static_wheel_load()
        );
    }

    #[test]
    fn at_rest_it_stays_at_rest() {
        let p = wagon();
        for z in [
            [[0.0; 2]; MAX_AXLES],
            [[-1e-3, -1.3e-3], [-0.8e-3, -1.0e-3], [0.0; 2], [0.0; 2]],
        ] {
            let mut body = TwoAxleWagon::new(p, 1e-4).unwrap();
            let forces = RailVehicle::set_static(&mut body, &z).unwrap();
            let d0 = *body.displacements();
            // Nothing accelerates: K d - F_gravity - F_contact to 1e-8 of a wheel load.
            let r = p.stiffness_matrix() * d0 - p.gravity_force() - p.contact_force(&forces);
            assert!(r.amax() < 1e-8 * p.static_wheel_load(), "{}", r.amax());
            // And 2 s of steps move it by less than a nanometre (5.6e-8 of the car
            // body's 16 mm static deflection, the rounding of the free wheelsets).
            for _ in 0..20_000 {
                RailVehicle::step(&mut body, &forces);
            }
            let drift = (body.displacements() - d0).amax();
            assert!(drift < 1e-9, "drift {drift}");
            // Above the axle boxes, under the static suspension forces.
            let mut top = SprungTwoAxleWagon::new(p, 1e-4).unwrap();
            let f = SprungVehicle::set_static(&mut top, &z).unwrap();
            let t0 = *top.displacements();
            for _ in 0..20_000 {
                SprungVehicle::step(&mut top, &f);
            }
            let drift = (top.displacements() - t0).amax();
            assert!(drift < 1e-9, "drift {drift}");
        }
    }

    /// What TrackContact carries above the axle boxes: the exchange's largest stable
    /// steps with nothing there and with the car body's effective mass at each axle
    /// box. Nothing is stable beyond 1 ms under both masters, so the track needs no
    /// inertia there.
    #[test]
    fn nothing_above_the_axle_boxes_is_stable_at_1_ms() {
        let p = wagon();
        let mut top = SprungTwoAxleWagon::new(p, 1e-4).unwrap();
        let z = [[-1.5e-3; 2], [-1.5e-3; 2], [0.0; 2], [0.0; 2]];
        SprungVehicle::set_static(&mut top, &z).unwrap();
        let support = crate::vehicle::CONTACT_STIFFNESS;
        let none = SprungVehicle::exchange_limits(&top, &z, 1e-4, support).unwrap();
        let m = p.effective_mass();
        let massive = crate::vehicle::exchange::linear_limits(
            &top,
            &p.wheelset(),
            SideFrameInertia::single(m),
            &z,
            1e-4,
            support,
        )
        .unwrap();
        println!(
            "effective mass {m:.0} kg; nothing above: {none:?}; the effective mass: {massive:?}"
        );
        // Measured: 14,671 kg; nothing above: Jacobi 15.2 ms, sequential 20.3 ms; the
        // effective mass: Jacobi 18.4 ms, sequential 20.3 ms.
        assert!((m - 14_671.0).abs() < 1.0, "{m}");
        assert!(none.jacobi > 10e-3 && none.sequential > 10e-3, "{none:?}");
        assert!(
            massive.jacobi > 1e-3 && massive.sequential > 1e-3,
            "{massive:?}"
        );
    }

    #[test]
    fn refusals_name_the_variable() {
        let mut p = wagon();
        p.wheelbase = 2.0;
        let e = LinearVehicle::validate(&p).unwrap_err().to_string();
        assert!(e.contains("wheelset[2].offset") && e.contains("4 m"), "{e}");
        let p = wagon();
        let e = TwoAxleWagon::new(p, 1.0).unwrap_err().to_string();
        assert!(e.contains("two-axle wagon"), "{e}");
    }
}
