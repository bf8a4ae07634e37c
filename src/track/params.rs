//! Track parameters, rail sections and the stability limit of the explicit scheme.

use super::*;

/// Rail cross-section data for the Timoshenko beam.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RailSection {
    /// Bending stiffness `EI` (N m^2).
    pub ei: f64,
    /// Shear stiffness `kappa A G` (N).
    pub kag: f64,
    /// Mass per metre `m` (kg/m).
    pub mass: f64,
    /// Rotary inertia per metre `m r^2` (kg m).
    pub rotary_inertia: f64,
}

impl RailSection {
    /// From material and section data (tables 4.1, 4.4, 5.1): Young's modulus `e` (Pa),
    /// shear modulus `g` (Pa), area `area` (m^2), second moment `inertia` (m^4),
    /// shear coefficient `kappa` (-), mass per metre `mass` (kg/m). `r^2 = I / A`.
    pub fn from_material(
        e: f64,
        g: f64,
        area: f64,
        inertia: f64,
        kappa: f64,
        mass: f64,
    ) -> Result<Self> {
        positive("track.rail.E", e, "Pa")?;
        positive("track.rail.G", g, "Pa")?;
        positive("track.rail.A", area, "m^2")?;
        positive("track.rail.I", inertia, "m^4")?;
        positive("track.rail.kappa", kappa, "")?;
        positive("track.rail.mass", mass, "kg/m")?;
        Ok(RailSection {
            ei: e * inertia,
            kag: kappa * area * g,
            mass,
            rotary_inertia: mass * inertia / area,
        })
    }

    /// Checks every field.
    pub fn validate(&self) -> Result<()> {
        check("track.rail.EI", self.ei)?;
        check("track.rail.kAG", self.kag)?;
        check("track.rail.mass", self.mass)?;
        check("track.rail.rotary_inertia", self.rotary_inertia)?;
        Ok(())
    }
}

/// End conditions of the rails.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RailEnds {
    /// `Z = theta = 0` at both ends (the thesis' model).
    Fixed,
    /// `Z = 0`, zero moment (`dtheta/dx = 0`) at both ends; used to verify the rail
    /// against the closed-form simply supported Timoshenko beam.
    Pinned,
}

/// The rail under a wheel between two grid nodes (`docs/MODEL.md`, "The rail between
/// nodes").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum RailBetweenNodes {
    /// The Timoshenko rail's shape between the nodes: (3.23)'s interpolation with the
    /// bending sag of the element's curvature, and the shear kink under the wheel's
    /// load in series with the contact ([`super::Track::shear_compliance`]).
    #[default]
    Beam,
    /// The thesis' linear interpolation of the two nodes (3.23), and (3.22) alone:
    /// the rail between nodes is too stiff by up to `dx / (4 kAG)`, a numerical
    /// roughness with the node spacing as its wavelength.
    Linear,
}

/// Track parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackParams {
    /// Number of sleeper spans `N` (>= 2).
    pub spans: usize,
    /// Grid nodes per span `n` (`dx = a / n`).
    pub nodes_per_span: usize,
    /// Sleeper spacing `a` (m).
    pub sleeper_spacing: f64,
    /// Distance between the two rail seats on a sleeper `L_s` (m); lever arm `L_s/2`.
    pub rail_seat_distance: f64,
    /// Rail section.
    pub rail: RailSection,
    /// Pad stiffness `K_p` (N/m).
    pub pad_stiffness: f64,
    /// Pad damping `C_p` (N s/m).
    pub pad_damping: f64,
    /// Ballast stiffness `K_b` at each rail seat (N/m).
    pub ballast_stiffness: f64,
    /// Ballast damping `C_b` at each rail seat (N s/m).
    pub ballast_damping: f64,
    /// Sleeper mass `m_s` (kg).
    pub sleeper_mass: f64,
    /// Sleeper roll moment of inertia `J_s` (kg m^2).
    pub sleeper_inertia: f64,
    /// Rail end conditions.
    pub ends: RailEnds,
    /// The rail under a wheel between grid nodes.
    pub between_nodes: RailBetweenNodes,
    /// How the rail pads and the ballast carry load: linear springs (the thesis) or
    /// supports that carry no tension beyond a preload (`docs/MODEL.md`, "Supports
    /// that lift").
    pub supports: Supports,
}

impl TrackParams {
    /// Checks every parameter; errors name the parameter, value and range.
    pub fn validate(&self) -> Result<()> {
        if self.spans < 2 {
            return Err(out_of_range("track.spans", self.spans as f64, ">= 2"));
        }
        if !(1..=MAX_NODES_PER_SPAN).contains(&self.nodes_per_span) {
            return Err(out_of_range(
                "track.nodes_per_span",
                self.nodes_per_span as f64,
                format!("1 <= track.nodes_per_span <= {MAX_NODES_PER_SPAN}"),
            ));
        }
        if self.spans.saturating_mul(self.nodes_per_span) > MAX_RAIL_SEGMENTS {
            return Err(out_of_range(
                "track.spans",
                self.spans as f64,
                format!(
                    "track.spans * track.nodes_per_span <= {MAX_RAIL_SEGMENTS} (here \
                     track.nodes_per_span = {}): the static solve of a longer grid needs \
                     more than about 100 MB",
                    self.nodes_per_span
                ),
            ));
        }
        check("track.sleeper_spacing", self.sleeper_spacing)?;
        check("track.rail_seat_distance", self.rail_seat_distance)?;
        self.rail.validate()?;
        check("track.pad.stiffness", self.pad_stiffness)?;
        check("track.pad.damping", self.pad_damping)?;
        check("track.ballast.stiffness", self.ballast_stiffness)?;
        check("track.ballast.damping", self.ballast_damping)?;
        check("track.sleeper.mass", self.sleeper_mass)?;
        check("track.sleeper.inertia", self.sleeper_inertia)?;
        self.supports.validate()?;
        Ok(())
    }

    /// Grid spacing `dx = a / n` (m).
    pub fn dx(&self) -> f64 {
        self.sleeper_spacing / self.nodes_per_span as f64
    }

    /// Track length `N a` (m).
    pub fn length(&self) -> f64 {
        self.sleeper_spacing * self.spans as f64
    }

    /// How far along a fixed track a wheel may run (m): to the last sleeper but one,
    /// `(N - 1) a`. The last span ends at the fixed rail end, which holds the rail at
    /// zero (`Z = theta = 0`): a wheel there rides a rail that cannot deflect, and one
    /// held at its static height presses it beyond the health bound within about 6 cm
    /// of the end (issue 38); its impact forces are 20 to 35 % high already. A run ends
    /// there ([`crate::Error::OffTrack`]).
    pub fn running_length(&self) -> f64 {
        self.sleeper_spacing * (self.spans as f64 - 1.0)
    }

    /// Critical time step of the explicit scheme (s) and the part of the model that
    /// sets it.
    ///
    /// The rail stencil's highest frequency is the maximum over wavenumbers of the
    /// larger eigenvalue of its 2x2 (deflection, rotation) symbol; the supports add at
    /// most the largest eigenvalue of one sleeper with its two pads and ballast (Weyl's
    /// inequality), so `dt_c = 2 / omega_max` is a sufficient bound for the undamped
    /// scheme. The explicit pad damper on the deflection branch adds the condition
    /// `lambda dt^2 + 2 eta dt <= 4`. For table 4.1 this gives the thesis' table 4.2.
    ///
    /// The wheel/rail contact spring is not in this bound, and does not need to be:
    /// [`TrackParams::critical_time_step_with_contact`] bounds the scheme with it and
    /// gives the same value, bit for bit, for every contact stiffness the adaptive law
    /// reaches on the thesis' tracks (table 4.4 at n = 1..10 up to 20 times the static
    /// load, a flat in the patch included); `examples/stability_limit.rs` measures the
    /// stepper's threshold with the contact spring, unchanged to 1e-6.
    pub fn critical_time_step(&self) -> (f64, String) {
        self.stability_bound(0.0)
    }

    /// [`TrackParams::critical_time_step`] with a contact spring of stiffness
    /// `contact_stiffness` `k_c` (N/m) between the rail under a wheel and ground: the
    /// linearised contact law `dP/d delta` at the largest force a run reaches, or will
    /// be allowed to reach (negative and NaN count as 0). Never above
    /// `critical_time_step`; the text names the contact, and says whether it lowers
    /// the limit.
    ///
    /// The contact force is evaluated explicitly from the rail deflection interpolated
    /// under the wheel (3.23) and shared between the two nodes around it (3.22), so
    /// linearised it adds `k_c v v^T` to the stiffness, `v = (1 - w, w)` on those
    /// nodes' deflections. Mass-normalised that is at most `d = k_c / (m dx)` times the
    /// projector on one node's deflection (`|v|^2 <= 1`, at most over a node), hence at
    /// most `d` times the projector on every deflection (Loewner order): a
    /// translation-invariant operator whose symbol is the rail's with `a + d` on the
    /// deflection diagonal. Its largest eigenvalue bounds the rail with the contact
    /// rigorously, and far more sharply than Weyl's `lambda + d`: the rail's highest
    /// mode is the rotation at the grid's shortest wave, to which the deflection is
    /// not coupled (the coupling goes as `sin q`, zero at `q = pi`), so the bound moves
    /// only once `a + d` nears the rotation branch: `k_c` above 3.3e10 N/m at n = 2
    /// and 6.4e10 N/m at n = 8 on the table 4.4 track, where 20 times the static load
    /// gives 3.9e9 N/m on a perfect wheel and 5.7e9 N/m with the 100 mm x 1.5 mm flat
    /// in the patch.
    /// The pad-damper condition takes `d` on its deflection branch. A wheel of mass
    /// `M_w` in place of ground is covered by passing `(1 + e) k_c` for any `e > 0`
    /// (the wheel's side of the spring then bounds as `(1 + 1/e) k_c / M_w`, orders of
    /// magnitude below the rail's frequencies).
    pub fn critical_time_step_with_contact(&self, contact_stiffness: f64) -> (f64, String) {
        let kc = contact_stiffness.max(0.0);
        let (dt0, text0) = self.stability_bound(0.0);
        if kc == 0.0 {
            return (dt0, text0);
        }
        let (dt, text) = self.stability_bound(kc);
        // Mathematically never above dt0; keep it so through rounding.
        if dt < dt0 * (1.0 - 1e-12) {
            (dt, text)
        } else {
            (
                dt.min(dt0),
                format!(
                    "{text0} (the contact stiffness {kc:.2e} N/m under the wheel does not lower it)"
                ),
            )
        }
    }

    /// The bound of [`TrackParams::critical_time_step_with_contact`] for contact
    /// stiffness `kc` (N/m, >= 0); with `kc = 0` that of
    /// [`TrackParams::critical_time_step`].
    fn stability_bound(&self, kc: f64) -> (f64, String) {
        // An instance's build, its resets and a study's cases ask for the same bound
        // again and again, and the scan below costs about 250 us (a tenth of the FMI
        // fuzz test's time): the last few are kept, per thread, by their exact inputs.
        // Everything kept is `Copy`: a thread-local that needs dropping registers a
        // destructor with the C library, which pins a loaded FMU's library until the
        // thread exits (dlclose then leaves it mapped; issue 38, N4).
        const KEPT: usize = 4;
        type Kept = [Option<(TrackParams, u64, StabilityBound)>; KEPT];
        thread_local! {
            static LAST: std::cell::Cell<Kept> = const { std::cell::Cell::new([None; KEPT]) };
        }
        let key = kc.to_bits();
        let mut last = LAST.get();
        let bound = match (last.iter().flatten()).find(|(p, k, _)| p == self && *k == key) {
            Some(&(_, _, b)) => b,
            None => {
                let b = self.stability_scan(kc);
                last.rotate_left(1);
                last[KEPT - 1] = Some((*self, key, b));
                LAST.set(last);
                b
            }
        };
        (bound.dt, bound.describe(self.dx()))
    }

    /// [`TrackParams::stability_bound`], computed: the rail's dispersion sampled at
    /// 4,097 wavenumbers, the supports' largest eigenvalue, the pads' damping.
    fn stability_scan(&self, kc: f64) -> StabilityBound {
        let r = &self.rail;
        let dx = self.dx();
        let m = r.mass;
        let mr2 = r.rotary_inertia;
        // The contact, mass-normalised, spread over every deflection (see above).
        let d = kc / (m * dx);
        let mut lam_rail: f64 = 0.0;
        let mut lam_z: f64 = 0.0;
        let samples = 4096;
        for i in 0..=samples {
            let q = std::f64::consts::PI * i as f64 / samples as f64;
            let s2 = 2.0 - 2.0 * q.cos();
            // `+ d` is exact for d = 0: the same bits as without the contact.
            let a = r.kag * s2 / (m * dx * dx) + d;
            let c = (r.ei * s2 / (dx * dx) + r.kag) / mr2;
            let b = r.kag * q.sin() / (dx * (m * mr2).sqrt());
            let l = 0.5 * (a + c) + (0.25 * (a - c) * (a - c) + b * b).sqrt();
            lam_rail = lam_rail.max(l);
            lam_z = lam_z.max(a);
        }
        // One sleeper with its two pads and ballast, mass-normalised (rail nodes m dx).
        let ls = 0.5 * self.rail_seat_distance;
        let support = |kp: f64, kb: f64| -> f64 {
            // dofs: Z_left, Z_right, Z_s, phi_s
            let mut k = Matrix4::<f64>::zeros();
            let seat = [(0usize, -ls), (1usize, ls)];
            for &(i, arm) in &seat {
                // pad between rail node i and the seat Z_s + arm phi
                let v = [
                    if i == 0 { 1.0 } else { 0.0 },
                    if i == 1 { 1.0 } else { 0.0 },
                    -1.0,
                    -arm,
                ];
                for p in 0..4 {
                    for q in 0..4 {
                        k[(p, q)] += kp * v[p] * v[q];
                    }
                }
            }
            k[(2, 2)] += 2.0 * kb;
            k[(3, 3)] += 2.0 * ls * ls * kb;
            let mass = [m * dx, m * dx, self.sleeper_mass, self.sleeper_inertia];
            for p in 0..4 {
                for q in 0..4 {
                    k[(p, q)] /= (mass[p] * mass[q]).sqrt();
                }
            }
            SymmetricEigen::new(k).eigenvalues.max()
        };
        let lam_sup = support(self.pad_stiffness, self.ballast_stiffness);
        let eta = support(self.pad_damping, 0.0);
        let lam = lam_rail + lam_sup;
        let dt_undamped = 2.0 / lam.sqrt();
        let lz = lam_z + lam_sup;
        let dt_damped = (-eta + (eta * eta + 4.0 * lz).sqrt()) / lz;
        let (dt, limiter) = if dt_damped < dt_undamped {
            (dt_damped, Limiter::PadDamper)
        } else {
            let c = (4.0 * r.ei / (dx * dx) + r.kag) / mr2;
            let limiter = if c >= lam_z {
                Limiter::Rotation
            } else if c >= lam_z - d {
                // The rotation would set it without the contact.
                Limiter::DeflectionUnderContact
            } else {
                Limiter::Shear
            };
            (dt_undamped, limiter)
        };
        StabilityBound {
            dt,
            limiter,
            contact_stiffness: kc,
        }
    }
}

/// Which stencil sets the track's stability bound ([`TrackParams::critical_time_step`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Limiter {
    /// The explicit rail-pad damper on the deflection stencil.
    PadDamper,
    /// The rail rotation (bending) stencil.
    Rotation,
    /// The deflection stencil, raised above the rotation by the contact spring.
    DeflectionUnderContact,
    /// The rail shear (deflection) stencil.
    Shear,
}

/// A stability bound as computed: the step (s), what sets it and the contact stiffness
/// (N/m) it was computed with; plain data, so that the thread's cache needs no drop.
#[derive(Debug, Clone, Copy, PartialEq)]
struct StabilityBound {
    dt: f64,
    limiter: Limiter,
    contact_stiffness: f64,
}

impl StabilityBound {
    /// The text naming what sets the bound, at node spacing `dx` (m).
    fn describe(&self, dx: f64) -> String {
        let kc = self.contact_stiffness;
        let with_contact = if kc > 0.0 {
            format!(" and the contact stiffness {kc:.2e} N/m under the wheel")
        } else {
            String::new()
        };
        let what = match self.limiter {
            Limiter::PadDamper => {
                return format!(
                    "the explicit rail-pad damper on the rail deflection stencil (dx = {dx:.4} m){with_contact}"
                );
            }
            Limiter::Rotation => "the rail rotation (bending) stencil",
            Limiter::DeflectionUnderContact => {
                "the rail deflection stencil under the contact spring"
            }
            Limiter::Shear => "the rail shear (deflection) stencil",
        };
        format!("{what} at dx = {dx:.4} m with pads and sleepers{with_contact}")
    }
}
