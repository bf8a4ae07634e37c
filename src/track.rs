//! Track: two Timoshenko rails (3.4, 3.5, 3.10) on discrete sleepers with bounce and
//! roll (3.6-3.9, 3.16), rail pads and ballast, solved by explicit central
//! differences in time and space (3.11, 3.12, 3.18).
//!
//! Grid: `dx = a / n`, nodes `k = 0..=K` with `K = N n` on each rail, sleepers at
//! every n-th node, both ends included (N spans = N + 1 sleepers). Rail ends are
//! fixed (`Z = theta = 0`). A point force `F` enters its node's equation as `F / dx`;
//! a moving wheel load is shared between the two nodes around it by (3.22) and the
//! rail displacement under the wheel is interpolated by (3.23).
//!
//! Sign conventions: displacements up, pad force (3.9)
//! `F = -K_p (Z_rail - Z_seat) - C_p (dZ_rail/dt - dZ_seat/dt)` acts up on the rail and
//! down on the sleeper; pad damper velocities are backward differences so the rail
//! update stays explicit; ballast damping uses central differences (3.18).
//!
//! The rail update is written as one stencil loop over both rails stored end to end
//! (the fixed end nodes separate them), with no allocation and no bounds checks, so
//! the compiler vectorises it.

use crate::error::{Error, Result, out_of_range, positive};
use crate::limits::{MAX_NODES_PER_SPAN, MAX_RAIL_SEGMENTS, check};
pub use crate::numerics::SimdLevel;
use crate::numerics::inlined;
use nalgebra::{DMatrix, DVector, Matrix4, SymmetricEigen};

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
    /// `Z = theta = 0` at both ends (the seed's model).
    Fixed,
    /// `Z = 0`, zero moment (`dtheta/dx = 0`) at both ends; used to verify the rail
    /// against the closed-form simply supported Timoshenko beam.
    Pinned,
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

    /// Critical time step of the explicit scheme (s) and the part of the model that
    /// sets it.
    ///
    /// The rail stencil's highest frequency is the maximum over wavenumbers of the
    /// larger eigenvalue of its 2x2 (deflection, rotation) symbol; the supports add at
    /// most the largest eigenvalue of one sleeper with its two pads and ballast (Weyl's
    /// inequality), so `dt_c = 2 / omega_max` is a sufficient bound for the undamped
    /// scheme. The explicit pad damper on the deflection branch adds the condition
    /// `lambda dt^2 + 2 eta dt <= 4`. For table 4.1 this gives the seed's table 4.2.
    ///
    /// The wheel/rail contact spring is not in this bound, and does not need to be:
    /// [`TrackParams::critical_time_step_with_contact`] bounds the scheme with it and
    /// gives the same value, bit for bit, for every contact stiffness the adaptive law
    /// reaches on the seed's tracks (table 4.4 at n = 1..10 up to 20 times the static
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
        let with_contact = if kc > 0.0 {
            format!(" and the contact stiffness {kc:.2e} N/m under the wheel")
        } else {
            String::new()
        };
        if dt_damped < dt_undamped {
            (
                dt_damped,
                format!(
                    "the explicit rail-pad damper on the rail deflection stencil (dx = {dx:.4} m){with_contact}"
                ),
            )
        } else {
            let c = (4.0 * r.ei / (dx * dx) + r.kag) / mr2;
            let what = if c >= lam_z {
                "the rail rotation (bending) stencil"
            } else if c >= lam_z - d {
                // The rotation would set it without the contact.
                "the rail deflection stencil under the contact spring"
            } else {
                "the rail shear (deflection) stencil"
            };
            (
                dt_undamped,
                format!("{what} at dx = {dx:.4} m with pads and sleepers{with_contact}"),
            )
        }
    }
}

/// A vertical point force on a rail.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLoad {
    /// Rail index: 0 left, 1 right.
    pub rail: usize,
    /// Position along the track (m), in (0, length).
    pub position: f64,
    /// Force pushing the rail down (N) (the contact force `P`).
    pub force: f64,
}

/// Precomputed update coefficients.
#[derive(Debug, Clone, Copy)]
struct Coeffs {
    zz: f64,
    /// `2 - 2 zz`: centre weight of the deflection update.
    zc: f64,
    zt: f64,
    tt: f64,
    /// `2 - 2 tt - t0`: centre weight of the rotation update.
    tc: f64,
    tz: f64,
    t0: f64,
    force: f64,
    s: SleeperCoeffs,
}

/// Pad forces and sleeper update (3.9, 3.18) written with the fewest constants (so
/// that the vectorised loop keeps them all in registers):
/// `F = c_p u_(j-1) - k_pc u_j` per rail seat, with `u` the rail deflection over the
/// seat minus the seat's displacement, and the implicit damping denominators of (3.18)
/// folded into the update weights.
#[derive(Debug, Clone, Copy)]
struct SleeperCoeffs {
    /// Half the rail seat distance `l_s / 2` (m).
    ls: f64,
    /// `k_p + c_p / dt` (N/m).
    kpc: f64,
    /// `c_p / dt` (N/m).
    cp: f64,
    /// Bounce weights of `Z_s(t_j)`, `Z_s(t_(j-1))` and of the pad forces.
    zz: f64,
    zzp: f64,
    zf: f64,
    /// Roll weights of `phi(t_j)`, `phi(t_(j-1))` and of the pad-force difference.
    pp: f64,
    ppp: f64,
    pf: f64,
}

impl Coeffs {
    /// Update coefficients of the explicit scheme for step `dt` (s).
    fn new(params: &TrackParams, dt: f64) -> Self {
        let p = params;
        let r = &p.rail;
        let dx = p.dx();
        let dt2 = dt * dt;
        let ls = 0.5 * p.rail_seat_distance;
        let kphi = 2.0 * ls * ls * p.ballast_stiffness;
        let cphi = 2.0 * ls * ls * p.ballast_damping;
        let zz = r.kag * dt2 / (r.mass * dx * dx);
        let tt = r.ei * dt2 / (r.rotary_inertia * dx * dx);
        let t0 = r.kag * dt2 / r.rotary_inertia;
        Coeffs {
            zz,
            zc: 2.0 - 2.0 * zz,
            zt: r.kag * dt2 / (2.0 * r.mass * dx),
            tt,
            tc: 2.0 - 2.0 * tt - t0,
            tz: r.kag * dt2 / (2.0 * r.rotary_inertia * dx),
            t0,
            force: dt2 / (r.mass * dx),
            s: {
                let zden = 1.0 / (1.0 + p.ballast_damping * dt / p.sleeper_mass);
                let pden = 1.0 / (1.0 + 0.5 * cphi * dt / p.sleeper_inertia);
                SleeperCoeffs {
                    ls,
                    kpc: p.pad_stiffness + p.pad_damping / dt,
                    cp: p.pad_damping / dt,
                    zz: (2.0 - 2.0 * p.ballast_stiffness * dt2 / p.sleeper_mass) * zden,
                    zzp: (p.ballast_damping * dt / p.sleeper_mass - 1.0) * zden,
                    zf: dt2 / p.sleeper_mass * zden,
                    pp: (2.0 - kphi * dt2 / p.sleeper_inertia) * pden,
                    ppp: (0.5 * cphi * dt / p.sleeper_inertia - 1.0) * pden,
                    pf: ls * dt2 / p.sleeper_inertia * pden,
                }
            },
        }
    }
}

/// Lanes of the widest vectors ([`LANES`]): the sleeper arrays and each rail's part of
/// a block are padded to a multiple of it, so that every loop runs in whole vectors.
use crate::numerics::LANES;

/// One cache line of values.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
struct Line([f64; LANES]);

/// Values starting on a cache line, so that with the guards a whole multiple of
/// [`LANES`] long, every block starts on one too and its centre loads and stores never
/// straddle two lines (a vector that does costs two loads).
#[derive(Debug, Clone)]
struct Aligned {
    lines: Vec<Line>,
    len: usize,
}

impl Aligned {
    /// `len` zeros.
    fn zeros(len: usize) -> Self {
        Aligned {
            lines: vec![Line([0.0; LANES]); len.div_ceil(LANES)],
            len,
        }
    }
}

impl std::ops::Deref for Aligned {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        // SAFETY: `Line` is `repr(C)` around `[f64; LANES]`, so the lines are
        // `LANES * lines.len() >= len` contiguous, initialised f64 values.
        unsafe { std::slice::from_raw_parts(self.lines.as_ptr().cast::<f64>(), self.len) }
    }
}

impl std::ops::DerefMut for Aligned {
    fn deref_mut(&mut self) -> &mut [f64] {
        // SAFETY: as in `deref`, and `&mut self` borrows the lines uniquely.
        unsafe { std::slice::from_raw_parts_mut(self.lines.as_mut_ptr().cast::<f64>(), self.len) }
    }
}

/// Track state and its explicit time stepper.
///
/// Storage: rail nodes are kept by *phase* within a span so that every loop runs over
/// contiguous memory, in whole vectors. With `N_s = N + 1` sleepers padded to `S`, a
/// multiple of `LANES` (8), phase block `p = k % n` holds node `k` of rail `r` at
/// `r S + k / n`, and the blocks are stored `1, 2, .., n - 1, 0` after `G = LANES`
/// unused values (as many behind; arrays start on a cache line, so every block does
/// too). Block 0 therefore holds the rail nodes above the sleepers, left rail then
/// right rail, in sleeper order, and the sleeper loop reads it directly. Every block
/// is stepped whole.
///
/// Slots past a rail's last node (one per rail in block 0 when `N_s < S`, more in
/// blocks `1..n`, which have `N` nodes) are padding. No real node reads a padding
/// slot, and padding slots read only padding, the rail ends and the guards (this is
/// why block 0 comes last: the slot one past it, which the last slot of block `n - 1`
/// reads, is the trailing guard and not node 1 of the left rail). Block 0's stencil
/// masks its padding and the rail ends to zero, so with fixed ends the padding, the
/// padded sleepers and their pads start at zero and stay there without a store after
/// the loops; pinned ends, whose end rotations move, clear the padding after every
/// step. Accessors return node order.
#[derive(Debug, Clone)]
pub struct Track {
    params: TrackParams,
    dt: f64,
    dt_critical: f64,
    /// `1 / dx` (1/m), for locating loads.
    inv_dx: f64,
    /// Nodes per rail `K + 1`.
    nk: usize,
    /// Sleepers `N_s = N + 1`.
    ns: usize,
    /// Sleepers padded to a multiple of [`LANES`], `S`: the length of the sleeper arrays and
    /// of each rail's part of a block.
    sp: usize,
    c: Coeffs,
    /// Storage slot of node `k` of the left rail (add `S` for the right rail).
    slot: Vec<usize>,
    /// Padding slots of the rail arrays (kept at zero).
    padding: Vec<usize>,
    /// Slots of the rail ends (first and last node of the left rail, then of the
    /// right rail), each with the slot of its inner neighbour node.
    ends_inner: [(usize, usize); 4],
    /// Rail deflection at t_j (m), phase-blocked.
    z: Aligned,
    /// Rail rotation at t_j (rad), phase-blocked.
    th: Aligned,
    z_prev: Aligned,
    th_prev: Aligned,
    zs: Aligned,
    ph: Aligned,
    zs_prev: Aligned,
    ph_prev: Aligned,
    /// Pad forces on the rails (N): left rail sleepers at `0..N_s`, right rail
    /// sleepers at `S..S + N_s`.
    pad: Aligned,
    /// Mask of block 0's new values (bit patterns, laid out as the block): all bits
    /// set over the interior nodes, none over the rail ends and the padding.
    keep: Aligned,
    simd: SimdLevel,
}

/// Node `k` and weight `w` of position `x` (m) on a rail of `nk` nodes spaced
/// `1 / inv_dx`: see [`Track::locate`].
#[inline]
fn locate(x: f64, inv_dx: f64, nk: usize) -> (usize, f64) {
    let s = (x * inv_dx).max(0.0);
    // Truncation equals floor for s >= 0 and avoids a libm call; through i64, whose
    // saturating conversion is one instruction and a select, not usize's dozen.
    let k = (s as i64 as usize).min(nk - 2);
    (k, (s - k as f64).clamp(0.0, 1.0))
}

/// Unused values in front of and behind the phase-blocked rail arrays, always zero:
/// the first slot of the first block in memory and the last slot of block `n - 1`
/// read one of them as a neighbour. A whole vector of them, so that blocks start on a
/// cache line.
const GUARD: usize = LANES;

/// First storage slot of phase block `p` of `n` whose rail parts are `sp` long: block
/// 0 comes last in memory (after blocks `1..n`), so that the one slot past it, which
/// the last slot of block `n - 1` reads as its right neighbour, is the trailing guard
/// (see [`Track`] on why the padding then needs no clearing).
#[inline(always)]
fn block_start(p: usize, n: usize, sp: usize) -> usize {
    // Not `(p + n - 1) % n`: an integer division in front of every loop.
    GUARD + (if p == 0 { n - 1 } else { p - 1 }) * 2 * sp
}

/// Pad forces (3.9) and sleeper update (3.18) for every sleeper: rail deflections
/// above the sleepers at t_j (`rl`, `rr`) and t_(j-1) (`rlp`, `rrp`), sleeper bounce
/// and roll at t_j (`zs`, `ph`) and t_(j-1) (`zsp`, `php`, overwritten with t_(j+1)),
/// pad forces out (`pl`, `pr`). Separate slice arguments (not a struct of slices) so
/// that the compiler knows they do not alias and vectorises without runtime checks.
/// Slices are as long as `zs`, a multiple of [`LANES`].
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn sleepers_body<const FMA: bool>(
    rl: &[f64],
    rr: &[f64],
    rlp: &[f64],
    rrp: &[f64],
    zs: &[f64],
    ph: &[f64],
    zsp: &mut [f64],
    php: &mut [f64],
    pl: &mut [f64],
    pr: &mut [f64],
    c: &SleeperCoeffs,
) {
    let m = zs.len();
    let (rl, rr, rlp, rrp) = (&rl[..m], &rr[..m], &rlp[..m], &rrp[..m]);
    let (ph, zsp, php) = (&ph[..m], &mut zsp[..m], &mut php[..m]);
    let (pl, pr) = (&mut pl[..m], &mut pr[..m]);
    for i in 0..m {
        let (z, f, zp, fp) = (zs[i], ph[i], zsp[i], php[i]);
        // Rail over seat, now and one step back: u = Z_rail - (Z_s -/+ l_s/2 phi).
        let (ul, ur) = (
            rl[i] - madd::<FMA>(-c.ls, f, z),
            rr[i] - madd::<FMA>(c.ls, f, z),
        );
        let (upl, upr) = (
            rlp[i] - madd::<FMA>(-c.ls, fp, zp),
            rrp[i] - madd::<FMA>(c.ls, fp, zp),
        );
        let fl = madd::<FMA>(-c.kpc, ul, c.cp * upl);
        let fr = madd::<FMA>(-c.kpc, ur, c.cp * upr);
        pl[i] = fl;
        pr[i] = fr;
        zsp[i] = madd::<FMA>(-c.zf, fl + fr, madd::<FMA>(c.zzp, zp, c.zz * z));
        php[i] = madd::<FMA>(c.pf, fl - fr, madd::<FMA>(c.ppp, fp, c.pp * f));
    }
}

/// `a b + c`: fused (one rounding) with `FMA`, else a product and a sum.
#[inline(always)]
fn madd<const FMA: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FMA { a.mul_add(b, c) } else { a * b + c }
}

/// One phase block of the rail stencil (3.12): centre nodes `zc`, `tc` with their
/// left (`zl`, `tl`) and right (`zr`, `tr`) neighbours, new values written over the
/// t_(j-1) values `zn`, `tn`. With `PAD` the block is block 0: it holds the sleeper
/// nodes, the pad forces `pad` enter, and the new values are masked by `keep` (bit
/// patterns: all ones keep a value, zero clears it), which holds the rail ends and
/// block 0's padding at exactly `+0.0` without a scalar store after the loop (a vector
/// load of the next step over a slot just written by a scalar store cannot take its
/// value from the store buffer and waits for the store to reach the cache).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn stencil_body<const PAD: bool, const FMA: bool>(
    zl: &[f64],
    zc: &[f64],
    zr: &[f64],
    tl: &[f64],
    tc: &[f64],
    tr: &[f64],
    zn: &mut [f64],
    tn: &mut [f64],
    pad: &[f64],
    keep: &[f64],
    c: &Coeffs,
) {
    let m = zc.len();
    let (zl, zr) = (&zl[..m], &zr[..m]);
    let (tl, tc, tr) = (&tl[..m], &tc[..m], &tr[..m]);
    let (zn, tn) = (&mut zn[..m], &mut tn[..m]);
    let (pad, keep) = if PAD {
        (&pad[..m], &keep[..m])
    } else {
        (&pad[..0], &keep[..0])
    };
    // `v` with its bits and-ed with `mask`'s.
    let masked = |v: f64, mask: f64| f64::from_bits(v.to_bits() & mask.to_bits());
    for i in 0..m {
        // (3.12) with the centre terms gathered: 5 multiply-adds per value.
        let znew = madd::<FMA>(
            -c.zt,
            tr[i] - tl[i],
            madd::<FMA>(c.zz, zr[i] + zl[i], madd::<FMA>(c.zc, zc[i], -zn[i])),
        );
        let tnew = madd::<FMA>(
            c.tz,
            zr[i] - zl[i],
            madd::<FMA>(c.tt, tr[i] + tl[i], madd::<FMA>(c.tc, tc[i], -tn[i])),
        );
        if PAD {
            zn[i] = masked(madd::<FMA>(c.force, pad[i], znew), keep[i]);
            tn[i] = masked(tnew, keep[i]);
        } else {
            zn[i] = znew;
            tn[i] = tnew;
        }
    }
}

/// One track step's loops over phase-blocked arrays of `n` blocks (see [`Track`]):
/// 1. pad forces at t_j (backward-difference damper velocities) and the sleeper
///    update (3.18), in place over the t_(j-1) sleeper arrays; block 0 holds the rail
///    nodes above the sleepers;
/// 2. the rail stencil block by block, each whole, written in place over the t_(j-1)
///    rail arrays, the pad forces entering block 0 and its mask `keep` clearing the
///    rail ends and its padding. Block p's left neighbours are block p - 1 (block
///    n - 1 one slot back for p = 0), its right neighbours block p + 1 (block 0 one
///    slot on for p = n - 1).
///
/// Inlined into [`step_body`], which is compiled once per SIMD level.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn kernels_body<const FMA: bool>(
    z: &[f64],
    th: &[f64],
    z_prev: &mut [f64],
    th_prev: &mut [f64],
    zs: &[f64],
    ph: &[f64],
    zs_prev: &mut [f64],
    ph_prev: &mut [f64],
    pad: &mut [f64],
    keep: &[f64],
    c: &Coeffs,
    n: usize,
) {
    let sp = zs.len();
    let b = 2 * sp;
    let block = |p: usize| block_start(p, n, sp)..block_start(p, n, sp) + b;
    {
        let (rl, rr) = z[block(0)].split_at(sp);
        let (rlp, rrp) = z_prev[block(0)].split_at(sp);
        let (pl, pr) = pad.split_at_mut(sp);
        sleepers_body::<FMA>(rl, rr, rlp, rrp, zs, ph, zs_prev, ph_prev, pl, pr, &c.s);
    }
    for p in 0..n {
        let centre = block(p);
        let left = if p == 0 {
            let l = block(n - 1);
            l.start - 1..l.end - 1
        } else {
            block(p - 1)
        };
        let right = if p + 1 == n {
            let r = block(0);
            r.start + 1..r.end + 1
        } else {
            block(p + 1)
        };
        let (zl, zc, zr) = (&z[left.clone()], &z[centre.clone()], &z[right.clone()]);
        let (tl, tc, tr) = (&th[left], &th[centre.clone()], &th[right]);
        let (zn, tn) = (&mut z_prev[centre.clone()], &mut th_prev[centre]);
        if p == 0 {
            stencil_body::<true, FMA>(zl, zc, zr, tl, tc, tr, zn, tn, pad, keep, c);
        } else {
            stencil_body::<false, FMA>(zl, zc, zr, tl, tc, tr, zn, tn, &[], &[], c);
        }
    }
}

/// [`Track::step`]: the loops of [`kernels_body`], then the wheel forces, end
/// conditions and padding; products and sums fused with `FMA`. The whole step is
/// compiled once per [`SimdLevel`], the glue with the loops.
#[inline(always)]
fn step_body<const FMA: bool>(t: &mut Track, loads: &[PointLoad]) {
    let (inv_dx, nk) = (t.inv_dx, t.nk);
    let Track {
        params,
        c,
        sp,
        z,
        th,
        z_prev,
        th_prev,
        zs,
        ph,
        zs_prev,
        ph_prev,
        pad,
        keep,
        padding,
        ends_inner,
        slot,
        ..
    } = t;
    let sp = *sp;
    let n = params.nodes_per_span;
    // The stencil overwrites every slot; pinned ends need their t_(j-1) rotation.
    let th_prev_ends = match params.ends {
        RailEnds::Pinned => ends_inner.map(|(e, _)| th_prev[e]),
        RailEnds::Fixed => [0.0; 4],
    };
    // 1-2. Sleepers and pads, then the rail stencil (see `kernels_body`).
    kernels_body::<FMA>(
        z, th, z_prev, th_prev, zs, ph, zs_prev, ph_prev, pad, keep, c, n,
    );
    // 3. Wheel forces on the new rail state, the rail ends (which the loops left at
    // zero) excepted.
    let mut apply = inlined(
        #[inline(always)]
        |k: usize, w: f64, rail: usize, force: f64| {
            let r = rail.min(1) * sp;
            if k > 0 {
                z_prev[slot[k] + r] -= c.force * (1.0 - w) * force;
            }
            if k + 2 < nk {
                z_prev[slot[k + 1] + r] -= c.force * w * force;
            }
        },
    );
    match loads {
        // A wheelset: both wheels at one position, located once.
        [a, b] if a.position == b.position => {
            let (k, w) = locate(a.position, inv_dx, nk);
            apply(k, w, a.rail, a.force);
            apply(k, w, b.rail, b.force);
        }
        _ => {
            for l in loads {
                let (k, w) = locate(l.position, inv_dx, nk);
                apply(k, w, l.rail, l.force);
            }
        }
    }
    match params.ends {
        // The padding stays at zero by itself (see `Track`).
        RailEnds::Fixed => {}
        RailEnds::Pinned => {
            // The end rotations are not zero, and padding next to an end reads them.
            for &s in padding.iter() {
                z_prev[s] = 0.0;
                th_prev[s] = 0.0;
            }
            // Ghost nodes: Z odd, theta even about the support.
            for (e, &(end, inner)) in ends_inner.iter().enumerate() {
                let sgn = if e % 2 == 0 { 1.0 } else { -1.0 };
                let (t0, ti, zi) = (th[end], th[inner], z[inner]);
                th_prev[end] = 2.0 * t0 - th_prev_ends[e]
                    + c.tt * (2.0 * ti - 2.0 * t0)
                    + sgn * c.tz * 2.0 * zi
                    - c.t0 * t0;
            }
        }
    }
    std::mem::swap(z, z_prev);
    std::mem::swap(th, th_prev);
    std::mem::swap(zs, zs_prev);
    std::mem::swap(ph, ph_prev);
}

/// Growth of a perturbation of the rails under a linear contact spring, for measuring
/// the stability threshold of the explicit scheme with the contact included
/// (`docs/VALIDATION.md`, section 3; `examples/stability_limit.rs`).
///
/// The track (`params`, no stability check on `dt`) starts from a pseudo-random
/// perturbation of every inner rail node (deflections of 1 um, rotations of 1 um / dx;
/// the same every call) and is stepped `steps` times at `dt` (s) with the force
/// `kc z_rail(x_w)` (N; `kc` in N/m) on the left rail under a wheel at
/// `x_w = x + v t` (m), as the coupled step applies the contact force. Returns the
/// largest `|Z|` and `|theta| dx` at the end over their largest at the start, infinite
/// once a value is not finite; it stops early, checking every 1,000 steps, once the
/// growth passes `stop`. Errors: the parameters' own ([`Track::new_without_stability_check`]).
pub fn perturbation_growth(
    params: TrackParams,
    dt: f64,
    kc: f64,
    (x, v): (f64, f64),
    steps: usize,
    stop: f64,
) -> Result<f64> {
    let mut t = Track::new_without_stability_check(params, dt)?;
    let nk = t.nodes();
    let dx = params.dx();
    // Deterministic pseudo-random start (xorshift), rail ends at zero.
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let (mut z, mut th) = (vec![0.0; 2 * nk], vec![0.0; 2 * nk]);
    for r in 0..2 {
        for k in 1..nk - 1 {
            z[r * nk + k] = 1e-6 * rnd();
            th[r * nk + k] = 1e-6 / dx * rnd();
        }
    }
    t.set_state(&z, &th, &z, &th);
    let amp = |t: &Track| {
        let mut a: f64 = 0.0;
        for r in 0..2 {
            for (z, th) in t.rail_z(r).into_iter().zip(t.rail_theta(r)) {
                if !(z.is_finite() && th.is_finite()) {
                    return f64::INFINITY;
                }
                a = a.max(z.abs()).max((th * dx).abs());
            }
        }
        a
    };
    let a0 = amp(&t);
    for j in 0..steps {
        let xw = x + v * j as f64 * dt;
        let force = kc * t.rail_z_at(0, xw);
        t.step(&[PointLoad {
            rail: 0,
            position: xw,
            force,
        }]);
        if j % 1000 == 999 && amp(&t) / a0 > stop {
            break;
        }
    }
    Ok(amp(&t) / a0)
}

impl Track {
    /// A track at rest and undeformed, stepped with `dt` (s). Refuses a step above
    /// the critical step with a message naming the limit.
    pub fn new(params: TrackParams, dt: f64) -> Result<Self> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        let (dtc, limit) = params.critical_time_step();
        if dt > dtc {
            return Err(Error::UnstableTimeStep {
                dt,
                critical: dtc,
                limit,
            });
        }
        let mut t = Self::new_unchecked(params, dt);
        t.dt_critical = dtc;
        Ok(t)
    }

    /// [`Track::new`] without the stability check: for measuring where the scheme
    /// becomes unstable (`examples/stability_limit.rs`). Above the stability limit
    /// the results grow without bound; use [`Track::new`] for everything else.
    pub fn new_without_stability_check(params: TrackParams, dt: f64) -> Result<Self> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        let mut t = Self::new_unchecked(params, dt);
        t.dt_critical = params.critical_time_step().0;
        Ok(t)
    }

    /// Builds the stepper without the stability check (validated parameters only).
    pub(crate) fn new_unchecked(params: TrackParams, dt: f64) -> Self {
        let n = params.nodes_per_span;
        let nk = params.spans * n + 1;
        let ns = params.spans + 1;
        let sp = ns.next_multiple_of(LANES);
        let c = Coeffs::new(&params, dt);
        let b = 2 * sp;
        let len = GUARD + n * b + GUARD;
        let slot: Vec<usize> = (0..nk).map(|k| block_start(k % n, n, sp) + k / n).collect();
        let mut used = vec![false; len];
        for &s in &slot {
            used[s] = true;
            used[s + sp] = true;
        }
        let padding = (GUARD..GUARD + n * b).filter(|&s| !used[s]).collect();
        let ends_inner = [
            (slot[0], slot[1]),
            (slot[nk - 1], slot[nk - 2]),
            (slot[0] + sp, slot[1] + sp),
            (slot[nk - 1] + sp, slot[nk - 2] + sp),
        ];
        // Block 0's mask: every bit set over its interior nodes, none over the rail
        // ends and the padding.
        let mut keep = Aligned::zeros(b);
        let start = block_start(0, n, sp);
        for k in (n..nk - 1).step_by(n) {
            keep[slot[k] - start] = f64::from_bits(u64::MAX);
            keep[slot[k] + sp - start] = f64::from_bits(u64::MAX);
        }
        Track {
            params,
            dt,
            dt_critical: f64::NAN,
            inv_dx: 1.0 / params.dx(),
            nk,
            ns,
            sp,
            c,
            slot,
            padding,
            ends_inner,
            z: Aligned::zeros(len),
            th: Aligned::zeros(len),
            z_prev: Aligned::zeros(len),
            th_prev: Aligned::zeros(len),
            zs: Aligned::zeros(sp),
            ph: Aligned::zeros(sp),
            zs_prev: Aligned::zeros(sp),
            ph_prev: Aligned::zeros(sp),
            pad: Aligned::zeros(2 * sp),
            keep,
            simd: SimdLevel::detect(),
        }
    }

    /// Parameters.
    pub fn params(&self) -> &TrackParams {
        &self.params
    }
    /// Time step (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// Critical time step (s).
    pub fn dt_critical(&self) -> f64 {
        self.dt_critical
    }
    /// Nodes per rail, `K + 1`.
    pub fn nodes(&self) -> usize {
        self.nk
    }
    /// Vector instructions the stepper uses.
    pub fn simd(&self) -> SimdLevel {
        self.simd
    }
    /// Makes the stepper use `level`; refused when this CPU lacks it.
    pub fn set_simd(&mut self, level: SimdLevel) -> Result<()> {
        if level > SimdLevel::detect() {
            return Err(Error::Unsupported(format!(
                "track.simd = {level:?}: this CPU supports up to {:?}",
                SimdLevel::detect()
            )));
        }
        self.simd = level;
        Ok(())
    }

    /// Storage slot of node `k` (0..=K) of `rail` (0 left, 1 right).
    #[inline]
    fn slot_of(&self, rail: usize, k: usize) -> usize {
        self.slot[k] + rail.min(1) * self.sp
    }

    /// Values of phase-blocked array `a` on `rail`, nodes 0..=K.
    fn rail_nodes<'a>(&'a self, a: &'a [f64], rail: usize) -> impl Iterator<Item = f64> + 'a {
        (0..self.nk).map(move |k| a[self.slot_of(rail, k)])
    }

    /// Phase-blocked array `a` in node order, both rails end to end.
    fn to_nodes(&self, a: &[f64]) -> Vec<f64> {
        self.rail_nodes(a, 0).chain(self.rail_nodes(a, 1)).collect()
    }

    /// Writes node-order values `v` (both rails end to end) into phase-blocked `a`
    /// (`sp`: the right rail's offset in a block).
    fn from_nodes(slot: &[usize], sp: usize, v: &[f64], a: &mut [f64]) {
        let nk = slot.len();
        for r in 0..2 {
            for (k, &s) in slot.iter().enumerate() {
                a[s + r * sp] = v[r * nk + k];
            }
        }
    }

    /// Rail deflections (m) of rail 0 (left) or 1 (right), nodes 0..=K.
    pub fn rail_z(&self, rail: usize) -> Vec<f64> {
        self.rail_nodes(&self.z, rail).collect()
    }
    /// Rail rotations (rad) of one rail, nodes 0..=K.
    pub fn rail_theta(&self, rail: usize) -> Vec<f64> {
        self.rail_nodes(&self.th, rail).collect()
    }
    /// Sleeper bounce displacements (m).
    pub fn sleeper_z(&self) -> &[f64] {
        &self.zs[..self.ns]
    }
    /// Sleeper roll angles (rad), positive raising the right seat.
    pub fn sleeper_roll(&self) -> &[f64] {
        &self.ph[..self.ns]
    }
    /// Pad forces on the rails (N, up on the rail) at the last step, per sleeper.
    pub fn pad_forces(&self, rail: usize) -> &[f64] {
        let at = rail.min(1) * self.sp;
        &self.pad[at..at + self.ns]
    }

    /// Largest absolute rail deflection or sleeper bounce displacement at t_j (m); NaN
    /// if any is NaN. For the health check of the solver (padding slots hold zeros).
    pub fn max_abs_displacement(&self) -> f64 {
        let mut m: f64 = 0.0;
        for &x in self.z.iter().chain(self.zs.iter()) {
            if x.is_nan() {
                return f64::NAN;
            }
            m = m.max(x.abs());
        }
        m
    }

    /// Sets every displacement (at t_j and t_(j-1)) and pad force to zero.
    pub fn reset(&mut self) {
        for v in [
            &mut self.z,
            &mut self.th,
            &mut self.z_prev,
            &mut self.th_prev,
            &mut self.zs,
            &mut self.ph,
            &mut self.zs_prev,
            &mut self.ph_prev,
            &mut self.pad,
        ] {
            v.iter_mut().for_each(|x| *x = 0.0);
        }
    }

    /// Node index and shape-function weight for a position: the load at `x` goes
    /// `(1 - w)` to node `k` and `w` to node `k + 1` (3.22).
    #[inline]
    pub fn locate(&self, x: f64) -> (usize, f64) {
        locate(x, self.inv_dx, self.nk)
    }

    /// Rail deflection (m) under position `x` on `rail`, interpolated by (3.23).
    #[inline]
    pub fn rail_z_at(&self, rail: usize, x: f64) -> f64 {
        let (k, w) = self.locate(x);
        (1.0 - w) * self.z[self.slot_of(rail, k)] + w * self.z[self.slot_of(rail, k + 1)]
    }

    /// Rail deflections (m) under position `x` on the left and right rail, (3.23):
    /// [`Track::rail_z_at`] of both rails, located once.
    #[inline(always)]
    pub fn rail_z_pair(&self, x: f64) -> [f64; 2] {
        let (k, w) = self.locate(x);
        let (s0, s1) = (self.slot[k], self.slot[k + 1]);
        let sp = self.sp;
        [
            (1.0 - w) * self.z[s0] + w * self.z[s1],
            (1.0 - w) * self.z[s0 + sp] + w * self.z[s1 + sp],
        ]
    }

    /// Advances the track from t_j to t_(j+1) under point loads applied at t_j.
    #[inline(always)]
    pub fn step(&mut self, loads: &[PointLoad]) {
        match self.simd {
            // No hardware FMA assumed at the baseline (the library `fma` is slow).
            SimdLevel::Baseline => step_body::<false>(self, loads),
            level => level.run(
                #[inline(always)]
                || step_body::<true>(self, loads),
            ),
        }
    }

    /// Number of unknowns of the static problem.
    fn static_size(&self) -> usize {
        4 * self.nk + 2 * self.ns
    }

    /// Symmetric stiffness matrix `K` of the discrete equations (rows scaled by dx so
    /// that `M = diag(m dx, m r^2 dx, m_s, J_s)`), unknowns ordered
    /// `[Z (both rails), theta (both rails), Z_s, phi_s]`. Fixed degrees of freedom have
    /// identity rows and columns. Dense: for tests and energy checks on short tracks
    /// (the static solve assembles its band directly, see [`Track::set_static`]).
    pub fn stiffness_matrix(&self) -> DMatrix<f64> {
        let n = self.static_size();
        let mut k = DMatrix::<f64>::zeros(n, n);
        self.stiffness_entries(|i, j, v| k[(i, j)] += v);
        k
    }

    /// Every contribution `v` to entry `(i, j)` of [`Track::stiffness_matrix`], in one
    /// fixed order (so any assembly sums each entry's contributions alike).
    fn stiffness_entries(&self, mut add: impl FnMut(usize, usize, f64)) {
        let p = &self.params;
        let r = &p.rail;
        let dx = p.dx();
        let nk = self.nk;
        let ns = self.ns;
        let (iz, it, izs, iph) = (0, 2 * nk, 4 * nk, 4 * nk + ns);
        let pinned = p.ends == RailEnds::Pinned;
        for rail in 0..2 {
            for node in 0..nk {
                let g = rail * nk + node;
                let end = node == 0 || node == nk - 1;
                // Deflection row.
                if end {
                    add(iz + g, iz + g, 1.0);
                } else {
                    add(iz + g, iz + g, 2.0 * r.kag / dx);
                    for nb in [g - 1, g + 1] {
                        let nb_end = nb % nk == 0 || nb % nk == nk - 1;
                        if !nb_end {
                            add(iz + g, iz + nb, -(r.kag / dx));
                        }
                        let sgn = if nb > g { 0.5 } else { -0.5 };
                        if !nb_end || pinned {
                            add(iz + g, it + nb, sgn * r.kag);
                        }
                    }
                }
                // Rotation row.
                if end && !pinned {
                    add(it + g, it + g, 1.0);
                } else if end {
                    let inner = if node == 0 { g + 1 } else { g - 1 };
                    let sgn = if node == 0 { -0.5 } else { 0.5 };
                    add(it + g, it + g, r.ei / dx + 0.5 * r.kag * dx);
                    add(it + g, it + inner, -(r.ei / dx));
                    add(it + g, iz + inner, sgn * r.kag);
                } else {
                    add(it + g, it + g, 2.0 * r.ei / dx + r.kag * dx);
                    for nb in [g - 1, g + 1] {
                        let nb_end = nb % nk == 0 || nb % nk == nk - 1;
                        if !nb_end || pinned {
                            add(it + g, it + nb, -(r.ei / dx));
                        }
                        let sgn = if nb > g { -0.5 } else { 0.5 };
                        if !nb_end {
                            add(it + g, iz + nb, sgn * r.kag);
                        }
                    }
                }
            }
        }
        let ls = 0.5 * p.rail_seat_distance;
        for i in 0..ns {
            let node = i * p.nodes_per_span;
            for (rail, arm) in [(0usize, -ls), (1usize, ls)] {
                let g = rail * nk + node;
                let rail_fixed = node == 0 || node == nk - 1;
                // pad energy 1/2 K_p (Z - Z_s - arm phi)^2
                let idx = [iz + g, izs + i, iph + i];
                let v = [1.0, -1.0, -arm];
                for a in 0..3 {
                    for b in 0..3 {
                        if rail_fixed && (a == 0 || b == 0) {
                            continue;
                        }
                        add(idx[a], idx[b], p.pad_stiffness * v[a] * v[b]);
                    }
                }
            }
            add(izs + i, izs + i, 2.0 * p.ballast_stiffness);
            add(iph + i, iph + i, 2.0 * ls * ls * p.ballast_stiffness);
        }
    }

    /// Puts the track in static equilibrium under `loads` (the same discrete equations
    /// with zero accelerations and velocities), solved directly.
    pub fn set_static(&mut self, loads: &[PointLoad]) -> Result<()> {
        let n = self.static_size();
        let (nk, ns, sp) = (self.nk, self.ns, self.sp);
        let mut f = DVector::<f64>::zeros(n);
        for l in loads {
            let (kk, w) = self.locate(l.position);
            let base = l.rail.min(1) * nk;
            for (node, share) in [(kk, 1.0 - w), (kk + 1, w)] {
                if node != 0 && node != nk - 1 {
                    f[base + node] -= share * l.force;
                }
            }
        }
        let x = self.solve_static_banded(f.as_slice()).ok_or_else(|| {
            out_of_range(
                "track.pad.stiffness",
                self.params.pad_stiffness,
                format!(
                    "a track whose pads and ballast hold the rails (static solve singular \
                         with track.pad.stiffness = {} N/m and track.ballast.stiffness = {} \
                         N/m: give both > 0)",
                    crate::error::num(self.params.pad_stiffness),
                    crate::error::num(self.params.ballast_stiffness)
                ),
            )
        })?;
        let xs = x.as_slice();
        Self::from_nodes(&self.slot, sp, &xs[..2 * nk], &mut self.z);
        Self::from_nodes(&self.slot, sp, &xs[2 * nk..4 * nk], &mut self.th);
        self.zs[..ns].copy_from_slice(&xs[4 * nk..4 * nk + ns]);
        self.ph[..ns].copy_from_slice(&xs[4 * nk + ns..]);
        self.z_prev.copy_from_slice(&self.z);
        self.th_prev.copy_from_slice(&self.th);
        self.zs_prev.copy_from_slice(&self.zs);
        self.ph_prev.copy_from_slice(&self.ph);
        let ls = 0.5 * self.params.rail_seat_distance;
        for i in 0..ns {
            // Block 0 holds the rail nodes above the sleepers.
            let s = block_start(0, self.params.nodes_per_span, sp) + i;
            let (zl, zr) = (self.z[s], self.z[s + sp]);
            self.pad[i] = -self.params.pad_stiffness * (zl - self.zs[i] + ls * self.ph[i]);
            self.pad[sp + i] = -self.params.pad_stiffness * (zr - self.zs[i] - ls * self.ph[i]);
        }
        Ok(())
    }

    /// Unknowns of [`Track::stiffness_matrix`] in order along the track: at each node
    /// `Z` and `theta` of the left rail, then of the right rail, then the sleeper's
    /// bounce and roll where a sleeper sits. Couplings then stay within a few places
    /// of the diagonal.
    fn static_order_along_track(&self) -> Vec<usize> {
        let (nk, ns, n) = (self.nk, self.ns, self.params.nodes_per_span);
        let mut order = Vec::with_capacity(self.static_size());
        for k in 0..nk {
            order.extend([k, 2 * nk + k, nk + k, 3 * nk + k]);
            if k % n == 0 {
                order.extend([4 * nk + k / n, 4 * nk + ns + k / n]);
            }
        }
        order
    }

    /// Solves `K x = f` for the symmetric positive definite stiffness matrix by
    /// Gaussian elimination on its band, unknowns taken in order along the track, the
    /// band assembled directly from [`Track::stiffness_entries`]: `O(N b)` memory and
    /// `O(N b^2)` time with half-bandwidth `b` of about 10, where the dense matrix
    /// would take `O(N^2)` and `O(N^3)`. `None` when a pivot is not positive: `K` is
    /// singular.
    fn solve_static_banded(&self, f: &[f64]) -> Option<Vec<f64>> {
        let order = self.static_order_along_track();
        let n = order.len();
        // Position along the track of each unknown.
        let mut pos = vec![0; n];
        for (i, &g) in order.iter().enumerate() {
            pos[g] = i;
        }
        let mut bw = 0;
        self.stiffness_entries(|i, j, v| {
            if v != 0.0 {
                bw = bw.max(pos[i].abs_diff(pos[j]));
            }
        });
        let w = 2 * bw + 1;
        let mut a = vec![0.0; n * w];
        let at = |i: usize, j: usize| i * w + j + bw - i;
        self.stiffness_entries(|i, j, v| {
            if v != 0.0 {
                a[at(pos[i], pos[j])] += v;
            }
        });
        let mut b: Vec<f64> = order.iter().map(|&g| f[g]).collect();
        let scale = (0..n).map(|i| a[at(i, i)].abs()).fold(0.0, f64::max);
        for c in 0..n {
            let pivot = a[at(c, c)];
            if pivot.is_nan() || pivot <= 1e-14 * scale {
                return None;
            }
            let end = (c + bw + 1).min(n);
            for i in c + 1..end {
                let l = a[at(i, c)] / pivot;
                if l == 0.0 {
                    continue;
                }
                for j in c + 1..end {
                    a[at(i, j)] -= l * a[at(c, j)];
                }
                b[i] -= l * b[c];
            }
        }
        let mut y = vec![0.0; n];
        for i in (0..n).rev() {
            let mut s = b[i];
            for j in i + 1..(i + bw + 1).min(n) {
                s -= a[at(i, j)] * y[j];
            }
            y[i] = s / a[at(i, i)];
        }
        let mut x = vec![0.0; n];
        for (i, &g) in order.iter().enumerate() {
            x[g] = y[i];
        }
        x.iter().all(|v| v.is_finite()).then_some(x)
    }

    /// Discrete energy of the undamped scheme (J): `1/2 v^T M v + 1/2 x_(j-1)^T K x_j`
    /// with `v = (x_j - x_(j-1)) / dt`; exactly conserved by the central-difference
    /// recurrence when all damping is zero and no load acts.
    pub fn discrete_energy(&self, k: &DMatrix<f64>) -> f64 {
        let p = &self.params;
        let dx = p.dx();
        let nk = self.nk;
        let ns = self.ns;
        let n = self.static_size();
        let mut x = DVector::<f64>::zeros(n);
        let mut xp = DVector::<f64>::zeros(n);
        let mut mass = DVector::<f64>::zeros(n);
        let (z, zp) = (self.to_nodes(&self.z), self.to_nodes(&self.z_prev));
        let (th, thp) = (self.to_nodes(&self.th), self.to_nodes(&self.th_prev));
        for i in 0..2 * nk {
            let end = i % nk == 0 || i % nk == nk - 1;
            x[i] = z[i];
            xp[i] = zp[i];
            mass[i] = p.rail.mass * dx;
            x[2 * nk + i] = th[i];
            xp[2 * nk + i] = thp[i];
            mass[2 * nk + i] = p.rail.rotary_inertia * if end { 0.5 * dx } else { dx };
        }
        for i in 0..ns {
            x[4 * nk + i] = self.zs[i];
            xp[4 * nk + i] = self.zs_prev[i];
            mass[4 * nk + i] = p.sleeper_mass;
            x[4 * nk + ns + i] = self.ph[i];
            xp[4 * nk + ns + i] = self.ph_prev[i];
            mass[4 * nk + ns + i] = p.sleeper_inertia;
        }
        let v = (&x - &xp) / self.dt;
        let kin = 0.5 * v.component_mul(&v).dot(&mass);
        let pot = 0.5 * xp.dot(&(k * &x));
        kin + pot
    }

    /// Sets the state at t_j and t_(j-1) directly (for tests and restarts): rail
    /// deflection and rotation of both rails end to end, then sleepers.
    pub fn set_state(&mut self, z: &[f64], th: &[f64], z_prev: &[f64], th_prev: &[f64]) {
        let (slot, sp) = (&self.slot, self.sp);
        Self::from_nodes(slot, sp, z, &mut self.z);
        Self::from_nodes(slot, sp, th, &mut self.th);
        Self::from_nodes(slot, sp, z_prev, &mut self.z_prev);
        Self::from_nodes(slot, sp, th_prev, &mut self.th_prev);
    }

    /// Changes the time step to `dt` (s), keeping the displacements at t_j and the
    /// backward-difference velocities `(x_j - x_(j-1)) / dt`: the t_(j-1) values are
    /// moved to `x_j - (x_j - x_(j-1)) dt_new / dt_old`. First-order accurate at the
    /// switch; used when a communication step is not a multiple of the step.
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        positive("solver.dt", dt, "s")?;
        if dt > self.dt_critical {
            return Err(Error::UnstableTimeStep {
                dt,
                critical: self.dt_critical,
                limit: self.params.critical_time_step().1,
            });
        }
        let ratio = dt / self.dt;
        for (cur, prev) in [
            (&self.z, &mut self.z_prev),
            (&self.th, &mut self.th_prev),
            (&self.zs, &mut self.zs_prev),
            (&self.ph, &mut self.ph_prev),
        ] {
            for (p, c) in prev.iter_mut().zip(cur.iter()) {
                *p = c - (c - *p) * ratio;
            }
        }
        self.c = Coeffs::new(&self.params, dt);
        self.dt = dt;
        Ok(())
    }

    /// Number of values in [`Track::state_vector`].
    pub fn state_len(&self) -> usize {
        1 + 8 * self.nk + 6 * self.ns
    }

    /// Everything that determines the continuation: the step, rails (node order, both
    /// rails end to end) and sleepers at t_j and t_(j-1), and the last pad forces.
    /// [`Track::set_state_vector`] restores it exactly.
    pub fn state_vector(&self) -> Vec<f64> {
        let mut v = Vec::with_capacity(self.state_len());
        v.push(self.dt);
        for a in [&self.z, &self.th, &self.z_prev, &self.th_prev] {
            v.extend(self.to_nodes(a));
        }
        let (ns, sp) = (self.ns, self.sp);
        for a in [&self.zs, &self.ph, &self.zs_prev, &self.ph_prev] {
            v.extend_from_slice(&a[..ns]);
        }
        v.extend_from_slice(&self.pad[..ns]);
        v.extend_from_slice(&self.pad[sp..sp + ns]);
        v
    }

    /// Restores a state written by [`Track::state_vector`] of a track with the same
    /// parameters.
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        if v.len() != self.state_len() {
            return Err(out_of_range(
                "track state length",
                v.len() as f64,
                format!("{} values for this grid", self.state_len()),
            ));
        }
        if v[0] != self.dt {
            self.change_dt(v[0])?;
        }
        let (nr, ns, sp) = (2 * self.nk, self.ns, self.sp);
        let mut rest = &v[1..];
        for a in [
            &mut self.z,
            &mut self.th,
            &mut self.z_prev,
            &mut self.th_prev,
        ] {
            let (head, tail) = rest.split_at(nr);
            Self::from_nodes(&self.slot, sp, head, a);
            rest = tail;
        }
        let (pl, pr) = self.pad.split_at_mut(sp);
        for a in [
            &mut self.zs[..ns],
            &mut self.ph[..ns],
            &mut self.zs_prev[..ns],
            &mut self.ph_prev[..ns],
            &mut pl[..ns],
            &mut pr[..ns],
        ] {
            let (head, tail) = rest.split_at(ns);
            a.copy_from_slice(head);
            rest = tail;
        }
        Ok(())
    }

    /// Sets sleeper bounce (m) and roll (rad) at t_j and t_(j-1).
    pub fn set_sleeper_state(&mut self, zs: &[f64], ph: &[f64], zs_prev: &[f64], ph_prev: &[f64]) {
        let ns = self.ns;
        self.zs[..ns].copy_from_slice(zs);
        self.ph[..ns].copy_from_slice(ph);
        self.zs_prev[..ns].copy_from_slice(zs_prev);
        self.ph_prev[..ns].copy_from_slice(ph_prev);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Table 4.1 / 4.4 track.
    fn seed_track(spans: usize, n: usize) -> TrackParams {
        TrackParams {
            spans,
            nodes_per_span: n,
            sleeper_spacing: 0.685,
            rail_seat_distance: 1.505,
            rail: RailSection::from_material(2.07e11, 81e9, 7.77e-3, 2.94e-5, 0.34, 60.0).unwrap(),
            pad_stiffness: 140e6,
            pad_damping: 45e3,
            ballast_stiffness: 40e6,
            ballast_damping: 50e3,
            sleeper_mass: 270.0,
            sleeper_inertia: 90.0,
            ends: RailEnds::Fixed,
        }
    }

    /// Mean period (s) from upward zero crossings of a signal sampled every dt.
    fn mean_period(sig: &[f64], dt: f64) -> f64 {
        let mean = sig.iter().sum::<f64>() / sig.len() as f64;
        let mut ups = Vec::new();
        for i in 1..sig.len() {
            let (a, b) = (sig[i - 1] - mean, sig[i] - mean);
            if a < 0.0 && b >= 0.0 {
                ups.push((i as f64 - 1.0 + a / (a - b)) * dt);
            }
        }
        (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64
    }

    #[test]
    fn simd_levels_and_storage_agree_bit_for_bit() {
        // Every SIMD level this CPU has gives the same bits as the plain node-order
        // recurrence written out here (the scheme of the module docs, one node at a
        // time): fused multiply-adds for AVX2 and AVX-512 (so those two agree bit for
        // bit), separate products for the baseline. The two roundings agree closely.
        for n in [1usize, 2, 3] {
            let p = seed_track(6, n);
            let dt = 0.9 * p.critical_time_step().0;
            let loads = [
                PointLoad {
                    rail: 0,
                    position: 2.3,
                    force: 1.1e5,
                },
                PointLoad {
                    rail: 1,
                    position: 2.3,
                    force: 0.7e5,
                },
            ];
            let steps = 3000;
            let node_order = |fma: bool| {
                // `a b + c`, fused (the library's correctly rounded `fma`) or not.
                let madd = |a: f64, b: f64, c: f64| if fma { a.mul_add(b, c) } else { a * b + c };
                let t = Track::new(p, dt).unwrap();
                let c = t.c;
                let nk = t.nodes();
                let ns = p.spans + 1;
                let ls = 0.5 * p.rail_seat_distance;
                let (mut z, mut th) = (vec![0.0; 2 * nk], vec![0.0; 2 * nk]);
                let (mut zp, mut thp) = (z.clone(), th.clone());
                let (mut zs, mut ph) = (vec![0.0; ns], vec![0.0; ns]);
                let (mut zsp, mut php) = (zs.clone(), ph.clone());
                let mut pad = vec![0.0; 2 * ns];
                for _ in 0..steps {
                    for i in 0..ns {
                        let (zz, f, zq, fq) = (zs[i], ph[i], zsp[i], php[i]);
                        let mut fl = [0.0; 2];
                        let s = &c.s;
                        for (r, sg) in [(0usize, -1.0), (1, 1.0)] {
                            let k = r * nk + i * n;
                            // (3.9): F = -k_p u - c_p (u - u_prev) / dt, u = rail over seat.
                            let u = z[k] - madd(sg * ls, f, zz);
                            let u_prev = zp[k] - madd(sg * ls, fq, zq);
                            fl[r] = madd(-s.kpc, u, s.cp * u_prev);
                            pad[r * ns + i] = fl[r];
                        }
                        zsp[i] = madd(-s.zf, fl[0] + fl[1], madd(s.zzp, zq, s.zz * zz));
                        php[i] = madd(s.pf, fl[0] - fl[1], madd(s.ppp, fq, s.pp * f));
                    }
                    for g in 1..2 * nk - 1 {
                        let (zc, tc) = (z[g], th[g]);
                        let zn = madd(c.zz, z[g + 1] + z[g - 1], madd(c.zc, zc, -zp[g]));
                        zp[g] = madd(-c.zt, th[g + 1] - th[g - 1], zn);
                        let tn = madd(c.tt, th[g + 1] + th[g - 1], madd(c.tc, tc, -thp[g]));
                        thp[g] = madd(c.tz, z[g + 1] - z[g - 1], tn);
                    }
                    for r in 0..2 {
                        for i in 0..ns {
                            zp[r * nk + i * n] = madd(c.force, pad[r * ns + i], zp[r * nk + i * n]);
                        }
                    }
                    for l in &loads {
                        let (k, w) = t.locate(l.position);
                        zp[l.rail * nk + k] -= c.force * (1.0 - w) * l.force;
                        zp[l.rail * nk + k + 1] -= c.force * w * l.force;
                    }
                    for e in [0, nk - 1, nk, 2 * nk - 1] {
                        zp[e] = 0.0;
                        thp[e] = 0.0;
                    }
                    std::mem::swap(&mut z, &mut zp);
                    std::mem::swap(&mut th, &mut thp);
                    std::mem::swap(&mut zs, &mut zsp);
                    std::mem::swap(&mut ph, &mut php);
                }
                let mut want = vec![dt];
                for a in [&z, &th, &zp, &thp, &zs, &ph, &zsp, &php, &pad] {
                    want.extend_from_slice(a);
                }
                want
            };
            let (unfused, fused) = (node_order(false), node_order(true));
            for level in SimdLevel::available() {
                let mut t = Track::new(p, dt).unwrap();
                t.set_simd(level).unwrap();
                for _ in 0..steps {
                    t.step(&loads);
                }
                let got = t.state_vector();
                let want = if level > SimdLevel::Baseline {
                    &fused
                } else {
                    &unfused
                };
                assert_eq!(want.len(), got.len());
                let first = want
                    .iter()
                    .zip(&got)
                    .position(|(a, b)| a.to_bits() != b.to_bits());
                assert!(
                    first.is_none(),
                    "n = {n}, {level:?}: phase-blocked storage differs from node order at {first:?} of {}",
                    want.len()
                );
            }
            // The two roundings: the rail deflection under the load agrees to 1e-12
            // of its size (rounding differences stay at rounding level).
            let nk = Track::new(p, dt).unwrap().nodes();
            let scale = unfused[1..1 + 2 * nk]
                .iter()
                .fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(scale > 1e-5, "the load must deflect the rail: {scale}");
            let worst = unfused[1..1 + 2 * nk]
                .iter()
                .zip(&fused[1..1 + 2 * nk])
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(
                worst < 1e-12 * scale,
                "fused and unfused differ by {worst:e} of {scale:e}"
            );
            assert!(
                worst > 0.0,
                "the fused recurrence must differ from the unfused one"
            );
        }
    }

    #[test]
    fn padding_and_rail_ends_stay_at_zero_without_clearing() {
        // Fixed ends: nothing clears the padding after a step, so it must stay at
        // exactly +0.0 by the storage order alone (block 0 last); the rail ends are
        // masked in the loop, loads in the end elements skip them. Pinned ends clear
        // the padding. Loads sit in the first and last elements of both rails.
        for (spans, n, ends) in [
            (6, 1, RailEnds::Fixed),
            (6, 2, RailEnds::Fixed),
            (9, 3, RailEnds::Fixed),
            (5, 4, RailEnds::Fixed),
            (6, 3, RailEnds::Pinned),
        ] {
            let mut p = seed_track(spans, n);
            p.ends = ends;
            let mut t = Track::new(p, 0.9 * p.critical_time_step().0).unwrap();
            let dx = p.dx();
            let len = p.length();
            let loads = [
                PointLoad {
                    rail: 0,
                    position: 0.3 * dx,
                    force: 1.0e5,
                },
                PointLoad {
                    rail: 1,
                    position: len - 0.6 * dx,
                    force: 0.8e5,
                },
                PointLoad {
                    rail: 0,
                    position: 0.55 * len,
                    force: 1.2e5,
                },
            ];
            assert!(!t.padding.is_empty() || n == 1);
            for _ in 0..2000 {
                t.step(&loads);
            }
            let what = format!("{spans} spans, n = {n}, {ends:?}");
            let zero = |a: &Aligned, s: usize| a[s].to_bits() == 0;
            for a in [&t.z, &t.th, &t.z_prev, &t.th_prev] {
                for &s in &t.padding {
                    assert!(zero(a, s), "{what}: padding slot {s} holds {:e}", a[s]);
                }
                let tail = GUARD + n * 2 * t.sp;
                for s in (0..GUARD).chain(tail..tail + GUARD) {
                    assert!(zero(a, s), "{what}: guard {s} holds {:e}", a[s]);
                }
            }
            for a in [&t.zs, &t.ph, &t.zs_prev, &t.ph_prev] {
                assert!(
                    a[t.ns..].iter().all(|v| v.to_bits() == 0),
                    "{what}: padded sleeper"
                );
            }
            for rail in 0..2 {
                let z = t.rail_z(rail);
                assert!(
                    z[0].to_bits() == 0 && z[t.nk - 1].to_bits() == 0,
                    "{what}: end Z"
                );
                assert!(
                    z[1] != 0.0 && z[t.nk - 2] != 0.0,
                    "{what}: the rail must move"
                );
                if ends == RailEnds::Fixed {
                    let th = t.rail_theta(rail);
                    assert!(
                        th[0].to_bits() == 0 && th[t.nk - 1].to_bits() == 0,
                        "{what}: end theta"
                    );
                }
            }
        }
    }

    #[test]
    fn critical_steps_reproduce_seed_table_4_2() {
        // Seed table 4.2 (table 4.1 track): n = 1..5, 10 -> 58, 46, 36, 29, 24, 13 us.
        let seed = [
            (1, 58e-6),
            (2, 46e-6),
            (3, 36e-6),
            (4, 29e-6),
            (5, 24e-6),
            (10, 13e-6),
        ];
        for (n, dtc) in seed {
            let (ours, _) = seed_track(20, n).critical_time_step();
            // The seed found its values by trial to 1 us.
            assert!((ours - dtc).abs() < 1.5e-6, "n = {n}: {ours} vs {dtc}");
        }
    }

    #[test]
    fn contact_spring_does_not_lower_the_critical_step() {
        // Table 4.4 contact (adaptive, K_w = 3.3443e10 N/m/rad, R_w = 0.475 m):
        // dP/d delta is 1.449e9 N/m at the static load (107.7 kN), 2.300e9 at 4 x (the
        // seed-grid reference run's 430 kN), 3.934e9 at 20 x, and at most 5.736e9 at
        // 20 x with the 100 mm x 1.5 mm flat in the patch (examples/stability_limit).
        // None of them moves the bound, by a single bit, at any grid.
        for n in 1..=10 {
            let p = seed_track(30, n);
            let (dt0, text0) = p.critical_time_step();
            assert_eq!(p.critical_time_step_with_contact(0.0), (dt0, text0.clone()));
            assert_eq!(p.critical_time_step_with_contact(-1.0).0, dt0);
            for kc in [1.449e9, 2.300e9, 3.934e9, 5.736e9, 2e10] {
                let (dt, text) = p.critical_time_step_with_contact(kc);
                assert_eq!(dt.to_bits(), dt0.to_bits(), "n = {n}, k_c = {kc}");
                assert!(text.starts_with(&text0), "{text}");
                assert!(text.contains("does not lower it"), "{text}");
            }
        }
        // The stepper agrees: with the 20 x static contact spring (flat in the patch)
        // over a rail node above a sleeper, n = 2, 0.99 dt_c stays bounded over 40,000
        // steps (1.8 s) and 1.01 dt_c blows up, as without the contact (the stepper's
        // own threshold is 1.0025 dt_c with and without it).
        let p = seed_track(30, 2);
        let (dtc, _) = p.critical_time_step();
        let x = 15.0 * 0.685;
        for kc in [0.0, 5.736e9] {
            let g =
                perturbation_growth(p, 0.99 * dtc, kc, (x, 0.0), 40_000, f64::INFINITY).unwrap();
            assert!(g < 10.0, "k_c = {kc}: {g}");
            let g =
                perturbation_growth(p, 1.01 * dtc, kc, (x, 0.0), 40_000, f64::INFINITY).unwrap();
            assert!(g > 1e6, "k_c = {kc}: {g}");
        }
    }

    #[test]
    fn contact_bound_holds_where_the_contact_sets_the_limit() {
        // 1e11 N/m (20 x the static load gives 3.9e9) does lower the limit at n = 2: the
        // bound is 0.5992 dt_c; the stepper's threshold with the spring over a sleeper
        // node is 0.6050 dt_c (1 % above the bound; examples/stability_limit), the
        // exact undamped one 0.6146 dt_c; Weyl's lambda + k_c / (m dx) would give
        // 0.5264 dt_c.
        let p = seed_track(30, 2);
        let (dt0, _) = p.critical_time_step();
        let (dt, text) = p.critical_time_step_with_contact(1e11);
        assert!((dt / dt0 - 0.5992).abs() < 1e-4, "{}", dt / dt0);
        assert!(text.contains("contact stiffness 1.00e11 N/m"), "{text}");
        assert!(!text.contains("does not lower it"), "{text}");
        let x = 15.0 * 0.685;
        let g = perturbation_growth(p, 0.99 * dt, 1e11, (x, 0.0), 40_000, f64::INFINITY).unwrap();
        assert!(g < 10.0, "{g}");
        let g = perturbation_growth(p, 1.02 * dt, 1e11, (x, 0.0), 40_000, f64::INFINITY).unwrap();
        assert!(g > 1e6, "{g}");
    }

    #[test]
    fn unstable_step_is_refused_and_limit_is_sharp() {
        let p = seed_track(10, 2);
        let (dtc, _) = p.critical_time_step();
        match Track::new(p, 1.01 * dtc) {
            Err(Error::UnstableTimeStep {
                critical, limit, ..
            }) => {
                assert_eq!(critical, dtc);
                assert!(limit.contains("rail"));
            }
            other => panic!("{other:?}"),
        }
        // Just below the limit the scheme stays bounded under a suddenly applied load...
        let load = [PointLoad {
            rail: 0,
            position: 3.0,
            force: 1e5,
        }];
        let mut t = Track::new(p, 0.98 * dtc).unwrap();
        for _ in 0..20_000 {
            t.step(&load);
        }
        let zmax = t.rail_z(0).iter().fold(0.0f64, |m, z| m.max(z.abs()));
        assert!(zmax < 5e-3, "{zmax}");
        // ...and 5% above it (bypassing the check) it blows up.
        let mut unstable = Track::new_unchecked(p, 1.05 * dtc);
        for _ in 0..20_000 {
            unstable.step(&load);
        }
        let blown = unstable
            .rail_z(0)
            .iter()
            .any(|z| !z.is_finite() || z.abs() > 1.0);
        assert!(blown);
    }

    #[test]
    fn settled_dynamic_response_equals_direct_static_solve() {
        let p = seed_track(8, 2);
        let x = 4.0 * 0.685 + 0.2;
        let loads = [
            PointLoad {
                rail: 0,
                position: x,
                force: 1.0e5,
            },
            PointLoad {
                rail: 1,
                position: x,
                force: 0.6e5,
            },
        ];
        let mut stat = Track::new(p, 40e-6).unwrap();
        stat.set_static(&loads).unwrap();
        let mut dynm = Track::new(p, 40e-6).unwrap();
        for _ in 0..45_000 {
            dynm.step(&loads);
        }
        // Average over the last 5000 steps: the rotation field keeps a faint, almost
        // undamped ringing near 4.9 kHz (damping reaches it only through the pads).
        let mut zavg = vec![0.0; dynm.z.len()];
        let mut thavg = vec![0.0; dynm.z.len()];
        for _ in 0..5_000 {
            dynm.step(&loads);
            for i in 0..zavg.len() {
                zavg[i] += dynm.z[i] / 5000.0;
                thavg[i] += dynm.th[i] / 5000.0;
            }
        }
        dynm.z.copy_from_slice(&zavg);
        dynm.th.copy_from_slice(&thavg);
        let zs = stat.rail_z_at(0, x);
        let zd = dynm.rail_z_at(0, x);
        assert!(((zs - zd) / zs).abs() < 1e-6, "{zs} vs {zd}");
        let thmax = stat.th.iter().fold(0.0f64, |m, t| m.max(t.abs()));
        let dz = (0..stat.z.len()).fold(0.0f64, |m, i| m.max((stat.z[i] - dynm.z[i]).abs()));
        let dth = (0..stat.z.len()).fold(0.0f64, |m, i| m.max((stat.th[i] - dynm.th[i]).abs()));
        assert!(
            dz < 1e-6 * zs.abs() && dth < 1e-6 * thmax,
            "{dz} {dth} {thmax}"
        );
        // Global equilibrium on a long track (ends far away): ballast carries the loads.
        let long = seed_track(40, 2);
        let mid = 20.0 * 0.685 + 0.2;
        let mut lt = Track::new(long, 40e-6).unwrap();
        lt.set_static(&[
            PointLoad {
                rail: 0,
                position: mid,
                force: 1.0e5,
            },
            PointLoad {
                rail: 1,
                position: mid,
                force: 0.6e5,
            },
        ])
        .unwrap();
        let ballast: f64 = lt
            .zs
            .iter()
            .map(|z| -2.0 * long.ballast_stiffness * z)
            .sum();
        assert!((ballast - 1.6e5).abs() < 1e-5 * 1.6e5, "{ballast}");
        // Roll: moment of the ballast reactions balances the unequal rail loads.
        let ls = 0.5 * long.rail_seat_distance;
        let moment: f64 = lt
            .ph
            .iter()
            .map(|f| 2.0 * ls * ls * long.ballast_stiffness * f)
            .sum();
        assert!(
            (moment - ls * (1.0e5 - 0.6e5)).abs() < 1e-5 * ls * 1e5,
            "{moment}"
        );
        // A static state is a fixed point of the stepper.
        let before = stat.z.clone();
        for _ in 0..100 {
            stat.step(&loads);
        }
        for (a, b) in before.iter().zip(stat.z.iter()) {
            assert!((a - b).abs() < 1e-12 * zs.abs());
        }
    }

    #[test]
    fn banded_static_solve_equals_dense_lu_and_refuses_a_singular_track() {
        for n in [1usize, 2, 5] {
            let p = seed_track(7, n);
            let t = Track::new(p, 20e-6).unwrap();
            let k = t.stiffness_matrix();
            let mut f = DVector::<f64>::zeros(k.nrows());
            // Loads on both rails at interior nodes, and a moment on a rotation.
            f[2] = -1e5;
            f[t.nk + 3] = -6e4;
            f[2 * t.nk + 4] = 250.0;
            let dense = k.clone().lu().solve(&f).unwrap();
            let banded = t.solve_static_banded(f.as_slice()).unwrap();
            let scale = dense.amax();
            for (a, b) in dense.iter().zip(&banded) {
                assert!((a - b).abs() < 1e-12 * scale, "n = {n}: {a} vs {b}");
            }
        }
        // No pads and no ballast: the sleepers float, the stiffness is singular.
        let mut p = seed_track(4, 2);
        p.pad_stiffness = 0.0;
        p.ballast_stiffness = 0.0;
        let mut t = Track::new(p, 20e-6).unwrap();
        let err = t
            .set_static(&[PointLoad {
                rail: 0,
                position: 1.0,
                force: 1e5,
            }])
            .unwrap_err();
        assert!(err.to_string().contains("singular"), "{err}");
    }

    #[test]
    fn long_track_static_solve_is_local_and_needs_no_dense_matrix() {
        // 4000 spans at n = 4: 16,001 nodes a rail and 72,006 unknowns, whose dense
        // stiffness matrix would take 41 GB. The band is assembled directly. The
        // deflection bowl around a wheelset in the middle must equal the one on a
        // 60-span track (30 spans, 20 m, of track on each side: the bowl decays over
        // about a metre: the two agree to 1e-13 of the peak here).
        let a = 0.685;
        let bowl = |spans: usize| {
            let mut t = Track::new(seed_track(spans, 4), 20e-6).unwrap();
            let x = 0.5 * spans as f64 * a + 0.3 * a;
            let loads = [
                PointLoad {
                    rail: 0,
                    position: x,
                    force: 1.2e5,
                },
                PointLoad {
                    rail: 1,
                    position: x,
                    force: 0.8e5,
                },
            ];
            t.set_static(&loads).unwrap();
            let mid = spans / 2 * 4;
            let (z0, z1) = (t.rail_z(0), t.rail_z(1));
            let near = |z: &[f64]| z[mid - 80..=mid + 80].to_vec();
            let sleepers = t.sleeper_z()[spans / 2 - 20..=spans / 2 + 20].to_vec();
            (near(&z0), near(&z1), sleepers, z0[4], z0[mid])
        };
        let start = std::time::Instant::now();
        let long = bowl(4000);
        let took = start.elapsed().as_secs_f64();
        let short = bowl(60);
        let peak = short.4.abs();
        assert!(peak > 1e-4, "the wheel must deflect the rail: {peak}");
        let worst = [
            (&long.0, &short.0),
            (&long.1, &short.1),
            (&long.2, &short.2),
        ]
        .iter()
        .flat_map(|(l, s)| l.iter().zip(s.iter()).map(|(a, b)| (a - b).abs()))
        .fold(0.0f64, f64::max);
        assert!(
            worst < 1e-11 * peak,
            "bowls differ by {worst:e} of {peak:e}"
        );
        assert!(long.3.abs() < 1e-12 * peak, "far field {:e}", long.3);
        assert!(took < 5.0, "static solve of 72,006 unknowns took {took} s");
    }

    #[test]
    fn sleeper_bounce_and_roll_match_single_mass_estimates() {
        // With pads that barely couple the sleepers to the rails, each sleeper is a
        // single mass on 2 K_b (bounce) and 2 (L_s/2)^2 K_b (roll).
        let mut p = seed_track(4, 2);
        p.pad_stiffness = 1.0;
        p.pad_damping = 0.0;
        p.ballast_damping = 0.0;
        let dt = 20e-6;
        let mut t = Track::new(p, dt).unwrap();
        let ns = p.spans + 1;
        let mut zs = vec![0.0; ns];
        let mut ph = vec![0.0; ns];
        zs[2] = 1e-3;
        ph[2] = 1e-3;
        t.set_sleeper_state(&zs, &ph, &zs.clone(), &ph.clone());
        let (mut bz, mut bp) = (Vec::new(), Vec::new());
        for _ in 0..50_000 {
            t.step(&[]);
            bz.push(t.sleeper_z()[2]);
            bp.push(t.sleeper_roll()[2]);
        }
        let f_bounce = 1.0 / mean_period(&bz, dt);
        let f_roll = 1.0 / mean_period(&bp, dt);
        let est_b =
            (2.0 * p.ballast_stiffness / p.sleeper_mass).sqrt() / (2.0 * std::f64::consts::PI);
        let ls = 0.5 * p.rail_seat_distance;
        let est_r = (2.0 * ls * ls * p.ballast_stiffness / p.sleeper_inertia).sqrt()
            / (2.0 * std::f64::consts::PI);
        assert!(
            ((f_bounce - est_b) / est_b).abs() < 1e-3,
            "{f_bounce} vs {est_b}"
        );
        assert!(
            ((f_roll - est_r) / est_r).abs() < 1e-3,
            "{f_roll} vs {est_r}"
        );
    }

    /// Closed-form frequency (Hz) of mode j of a simply supported Timoshenko beam.
    fn timoshenko_ss(r: &RailSection, len: f64, j: usize) -> f64 {
        let k = j as f64 * std::f64::consts::PI / len;
        // (kAG k^2 - m w^2)(EI k^2 + kAG - m r^2 w^2) = (kAG k)^2, lower root.
        let a = r.mass * r.rotary_inertia;
        let b = -(r.mass * (r.ei * k * k + r.kag) + r.rotary_inertia * r.kag * k * k);
        let c = r.kag * k * k * r.ei * k * k;
        let w2 = (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
        w2.sqrt() / (2.0 * std::f64::consts::PI)
    }

    #[test]
    fn free_rail_converges_to_timoshenko_beam_at_second_order() {
        // Unsupported rail (no pads), pinned ends, started in the exact mode shape.
        let mut errs = Vec::new();
        for n in [4usize, 8, 16] {
            let mut p = seed_track(4, n);
            p.pad_stiffness = 0.0;
            p.pad_damping = 0.0;
            p.ends = RailEnds::Pinned;
            let len = p.length();
            let j = 2;
            let exact = timoshenko_ss(&p.rail, len, j);
            let kw = j as f64 * std::f64::consts::PI / len;
            // Rotation amplitude of the bending mode for unit deflection.
            let w2 = (2.0 * std::f64::consts::PI * exact).powi(2);
            let b = (p.rail.kag * kw * kw - p.rail.mass * w2) / (p.rail.kag * kw);
            let (dtc, _) = p.critical_time_step();
            let dt = 0.5 * dtc;
            let mut t = Track::new(p, dt).unwrap();
            let nk = t.nodes();
            let dx = p.dx();
            let mut z = vec![0.0; 2 * nk];
            let mut th = vec![0.0; 2 * nk];
            for i in 0..nk {
                let x = i as f64 * dx;
                z[i] = 1e-3 * (kw * x).sin();
                th[i] = 1e-3 * b * (kw * x).cos();
            }
            t.set_state(&z, &th, &z.clone(), &th.clone());
            let probe = nk / (2 * j);
            let steps = (20.0 / exact / dt) as usize;
            let mut sig = Vec::with_capacity(steps);
            for _ in 0..steps {
                t.step(&[]);
                sig.push(t.rail_z(0)[probe]);
            }
            let f = 1.0 / mean_period(&sig, dt);
            errs.push(((f - exact) / exact).abs());
        }
        // Errors fall by about 4x per halving of dx (second order).
        for w in errs.windows(2) {
            let order = (w[0] / w[1]).log2();
            assert!((1.8..2.3).contains(&order), "{errs:?}");
        }
        assert!(errs[2] < 1e-2, "{errs:?}");
    }

    #[test]
    fn undamped_discrete_energy_is_conserved_over_1e5_steps() {
        let mut p = seed_track(6, 2);
        p.pad_damping = 0.0;
        p.ballast_damping = 0.0;
        let (dtc, _) = p.critical_time_step();
        let mut t = Track::new(p, 0.9 * dtc).unwrap();
        // Start from a static deflection then release the load.
        t.set_static(&[PointLoad {
            rail: 0,
            position: 2.0,
            force: 1e5,
        }])
        .unwrap();
        let k = t.stiffness_matrix();
        let e0 = t.discrete_energy(&k);
        let mut worst: f64 = 0.0;
        for s in 0..100_000 {
            t.step(&[]);
            if s % 1000 == 0 {
                worst = worst.max(((t.discrete_energy(&k) - e0) / e0).abs());
            }
        }
        assert!(worst < 1e-9, "relative energy drift {worst}");
    }
}
