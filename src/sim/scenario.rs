//! What a simulation is built from: [`Scenario`], the track ([`TrackSpec`]), the
//! vehicle or load ([`VehicleSpec`]), the wheelsets behind the leading one, the endless
//! track's window, hanging sleepers and the side frames at the axle boxes. The thesis'
//! parameter sets as ready-made scenarios are in `presets.rs`.

use crate::contact::{ContactModel, RoughnessSpectrum};
use crate::track::{ProfileSpec, RailProfile};
use crate::track::{RailBetweenNodes, Supports, TrackParams};
use crate::vehicle::{
    CarrierSpec, LumpedTrackParams, LumpedWheelParams, RollPlaneParams, SideFrameInertia,
};
use crate::wheel::{FlatSpec, OutOfRoundness};
use std::sync::Arc;

/// Which track model carries the loads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TrackSpec {
    /// Two Timoshenko rails on discrete sleepers (chapter 3).
    Discrete(TrackParams),
    /// The chapter-2 lumped track mass under each wheel.
    Lumped(LumpedTrackParams),
}

/// What loads the track.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VehicleSpec {
    /// The six-DOF roll-plane vehicle (chapter 3).
    RollPlane(RollPlaneParams),
    /// A vehicle on several wheelsets, any kind of the registry
    /// ([`crate::vehicle::VEHICLE_KINDS`]): the half-car bogie, the four-axle wagon, the
    /// two-axle wagon, on the leading wheelset and the trailing ones
    /// ([`Scenario::trailing`]) at the offsets its [`crate::vehicle::CarrierModel::offsets`]
    /// name.
    Carrier(CarrierSpec),
    /// The chapter-2 lumped wheel on each rail.
    LumpedWheels(LumpedWheelParams),
    /// A constant moving load on each rail `[left, right]` (N) (chapter 4).
    ConstantLoad([f64; 2]),
    /// The roll-plane vehicle's wheelsets on the track with their primary suspensions,
    /// cut above them ([`crate::vehicle::PrimaryLink`]): the bogie above is a
    /// co-simulation partner that sets each wheelset's side frames' motion
    /// ([`crate::sim::Simulation::set_side_frames_of`]) and reads the mean primary
    /// forces ([`crate::sim::Simulation::primary_of`]). Of the vehicle's parameters
    /// only the wheelset's (mass, roll inertia), the primary suspension's (stiffness,
    /// damping, spacing) and gravity are used.
    AxleBox {
        /// The vehicle, for its wheelset and primary suspension.
        vehicle: RollPlaneParams,
        /// The side frames above the axle boxes, whose inertia the track carries over
        /// each communication step ([`crate::vehicle::SideFrameInertia`]).
        side_frames: SideFrameSpec,
        /// Static wheel loads `[left, right]` (N): the whole vehicle's
        /// ([`RollPlaneParams::static_wheel_load`]) or the bogie model's.
        static_load: [f64; 2],
    },
    /// Wheels moved from outside (co-simulation with an external vehicle): the wheel
    /// displacements and the axle angle are inputs
    /// ([`crate::sim::Simulation::set_wheel_inputs`]); `static_load` `[left, right]`
    /// (N) is the load the external vehicle puts on each wheel at rest, used for the
    /// static start and for calibrating `K_w`.
    External {
        /// Static wheel loads `[left, right]` (N).
        static_load: [f64; 2],
    },
}

impl VehicleSpec {
    /// The vehicle of the registry's kind `spec`: the roll-plane vehicle rides on each
    /// wheelset, its own on each; any other kind is one vehicle over its wheelsets.
    pub fn of_kind(spec: CarrierSpec) -> VehicleSpec {
        match spec {
            CarrierSpec::RollPlane(p) => VehicleSpec::RollPlane(p),
            c => VehicleSpec::Carrier(c),
        }
    }

    /// The vehicle on several wheelsets, behind its interface; `None` for a vehicle or
    /// load on each wheelset.
    pub fn carrier(&self) -> Option<&dyn crate::vehicle::CarrierModel> {
        match self {
            VehicleSpec::Carrier(c) => Some(c.model()),
            _ => None,
        }
    }
}

/// A complete simulation set-up.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Name of the parameter set.
    pub name: String,
    /// Track.
    pub track: TrackSpec,
    /// Vehicle or load.
    pub vehicle: VehicleSpec,
    /// Nominal wheel radius `R_w` (m).
    pub wheel_radius: f64,
    /// Flats on the left (0) and right (1) wheel.
    pub flats: [Vec<FlatSpec>; 2],
    /// Contact law.
    pub contact_model: ContactModel,
    /// Radial spring stiffness `K_w` (N/m/rad); 0 calibrates it from `hertz_coefficient`
    /// and the static wheel load by (2.25, 2.26).
    pub kw: f64,
    /// Hertz coefficient `C_H` (N/m^1.5), for the Hertz law and for calibrating `K_w`.
    pub hertz_coefficient: f64,
    /// Forward speed `V` (m/s).
    pub speed: f64,
    /// Wheel position along the track at t = 0 (m).
    pub start_position: f64,
    /// Time step (s); 0 takes the converged default.
    pub dt: f64,
    /// Observation points (m along the track, at most [`crate::limits::MAX_SITES`]):
    /// what the discrete track feels there, with extremes ([`super::Site`]).
    pub sites: Vec<f64>,
    /// The wheelsets behind the leading one (at most
    /// [`crate::limits::MAX_WHEELSETS`] in all), each carrying the same vehicle model
    /// as the leading one (a roll-plane vehicle, constant loads or external wheels),
    /// with its own flats. The leading wheelset has [`Scenario::flats`].
    pub trailing: Vec<TrailingWheelset>,
    /// `None`: the discrete track is fixed (its `spans` from its parameters). `Some`: an
    /// endless track, a window that moves with the wheelsets by whole sleeper spans
    /// (its length follows from the window and the wheelsets; the track parameters'
    /// `spans` is ignored).
    pub window: Option<TrackWindow>,
    /// Hanging (voided) sleepers of the discrete track; `None`: every sleeper on the
    /// ballast.
    pub voids: Option<VoidedSleepers>,
    /// The rails' vertical profiles `[left, right]` along the line (measured heights,
    /// a dipped weld or joint); default: ideal rails.
    pub rails: [RailProfile; 2],
    /// The leading wheelset's measured out-of-roundness `[left, right]`; `None`: round
    /// but for the flats.
    pub roundness: [Option<Arc<OutOfRoundness>>; 2],
    /// The rails' profile drawn from a standard spectrum and the rails' and wheels'
    /// short-wave roughness, on top of the above; default: none.
    pub random: RandomIrregularities,
}

/// Irregularities drawn at random from standard spectra, on top of the measured ones
/// (`docs/MODEL.md`, "Random rail profiles and roughness"): the same fields draw the
/// same rails and wheels, on any track and window.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RandomIrregularities {
    /// Both rails' vertical profile from a track spectrum; its ramp, from the leading
    /// wheelset's start position, also brings in the rails' roughness.
    pub profile: Option<ProfileSpec>,
    /// Short-wave roughness of the rails and the wheels.
    pub roughness: Option<Roughness>,
}

/// Short-wave roughness of the rails and the wheels from one-third octave band spectra,
/// seen through the contact patch ([`crate::contact::contact_filter`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Roughness {
    /// Each rail's spectrum (the rails drawn independently); `None`: smooth rails.
    pub rail: Option<Arc<RoughnessSpectrum>>,
    /// Each wheel's spectrum (every wheel drawn independently); `None`: smooth wheels.
    pub wheel: Option<Arc<RoughnessSpectrum>>,
    /// The seed.
    pub seed: u64,
    /// The contact patch's length along the rail (m) the roughness is averaged over; 0:
    /// the Hertz patch under the static wheel load ([`crate::contact::hertz_half_length`]).
    pub patch_length: f64,
}

/// Sleepers in a row that hang from the rails with a gap above the ballast, which
/// carries them only once the gap has closed and never pulls
/// ([`crate::track::Track::set_sleeper_gaps`]; `docs/MODEL.md`, "Supports that lift").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VoidedSleepers {
    /// Position along the line of the first (m): the sleeper nearest it.
    pub position: f64,
    /// How many, from the first in the direction of travel (1 to 100).
    pub sleepers: usize,
    /// The gap under each (m, 0 to [`crate::track::MAX_VOID_GAP`]; 0: resting on the
    /// ballast, which does not hold it down).
    pub gap: f64,
}

impl VoidedSleepers {
    /// The gap under each sleeper of a track whose node 0 lies at `origin` (m, line
    /// coordinates) with `ns` sleepers `spacing` (m) apart: `None` on the ballast.
    ///
    /// Errors: `sleepers` outside 1 to 100 (`track.void.sleepers`), `position` not
    /// finite (`track.void.position`), `gap` outside 0 to 0.05 m (`track.void.gap`).
    pub fn gaps(
        &self,
        origin: f64,
        ns: usize,
        spacing: f64,
    ) -> crate::error::Result<Vec<Option<f64>>> {
        if !(1..=100).contains(&self.sleepers) {
            return Err(crate::error::out_of_range(
                "track.void.sleepers",
                self.sleepers as f64,
                "0 <= track.void.sleepers <= 100 (0: none)",
            ));
        }
        crate::error::finite("track.void.position", self.position, "m")?;
        let max = crate::track::MAX_VOID_GAP;
        if !(0.0..=max).contains(&self.gap) {
            return Err(crate::error::out_of_range(
                "track.void.gap",
                self.gap,
                format!("0 m <= track.void.gap <= {max} m"),
            ));
        }
        // Sleepers lie at whole multiples of the spacing in line coordinates.
        let first = (self.position / spacing).round() as i64;
        let node0 = (origin / spacing).round() as i64;
        Ok((0..ns)
            .map(|i| {
                let k = node0 + i as i64 - first;
                (0..self.sleepers as i64).contains(&k).then_some(self.gap)
            })
            .collect())
    }
}

/// A wheelset behind the leading one.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TrailingWheelset {
    /// Distance `d_k > 0` (m) behind the leading wheelset.
    pub offset: f64,
    /// Flats on the left (0) and right (1) wheel.
    pub flats: [Vec<FlatSpec>; 2],
    /// Measured out-of-roundness of the left (0) and right (1) wheel.
    pub roundness: [Option<Arc<OutOfRoundness>>; 2],
}

/// The window of an endless track: the lengths of track kept ahead of the leading
/// wheelset and behind the last one. The window spans
/// `ceil((ahead + behind + 2 layer + d_max) / a) + 1` sleeper spans and moves forward by
/// whole spans whenever less than `ahead` (and the layer) remains in front of the
/// leading wheelset; new track enters at rest, and the window's rail ends are fixed. Sleepers lie at whole multiples of
/// the spacing `a` in line coordinates, as on a fixed track starting at 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackWindow {
    /// Track kept ahead of the leading wheelset (m).
    pub ahead: f64,
    /// Track kept behind the last wheelset (m).
    pub behind: f64,
    /// A graded damping layer of this length (m) beyond `ahead` and `behind` at each
    /// end ([`crate::track::Track::set_absorbing_ends`]); 0 (the default): none, the
    /// window's ends reflect. Measured (issue 29, docs/VALIDATION.md): a layer takes
    /// the fast waves above 1.5 kHz but reflects the slow ones near the rail's
    /// pinned-pinned frequency, where a window's error lies, more than the same length
    /// of plain track does; kept for that study, not recommended.
    pub layer: f64,
    /// The layer's largest damping rate (1/s), at the rail ends.
    pub layer_rate: f64,
    /// Exact window ends with this memory (s) ([`crate::track::Track::set_exact_ends`]);
    /// 0 (the default): none; at least 128 steps. Measured (issue 29, docs/VALIDATION.md):
    /// a 4 m a side window with 0.1 s of memory is within 0.39 % of the static load of a
    /// 600-span track over 1 s, where the plain converged 20 m window is within 0.53 %;
    /// but evaluated directly its convolutions cost far more than the track (35 to 50 s
    /// of wall a simulated second at 0.1 s): a study tool, engine only, not for
    /// production runs. Refused with an absorbing layer, voided sleepers or tensionless
    /// supports.
    pub exact_memory: f64,
}

impl TrackWindow {
    /// The converged window: 20 m ahead, 20 m behind (60 spans of table 4.4 for one
    /// wheelset). Against a 600-span fixed track, the reference flat case's peak is
    /// within 0.001 % and its whole force history within 0.53 % of the static load
    /// (`examples/window_study.rs`, `docs/VALIDATION.md`). The waves an impact sends
    /// along the rails come back from the window's fixed ends: 8 m a side gives the
    /// peak within 0.01 % but the history only within 3.5 %.
    pub const CONVERGED: TrackWindow = TrackWindow {
        ahead: 20.0,
        behind: 20.0,
        layer: 0.0,
        layer_rate: 0.0,
        exact_memory: 0.0,
    };

    /// The FMUs' default track (`track.window.ahead` = `track.window.behind` = 10 m,
    /// issue 29): the window that costs what the thesis' fixed 30-span track costs a
    /// step, and runs as long as the study does. On the reference flat case over 0.95 s
    /// against a 600-span track, its peak is within 0.001 % and its force history
    /// within 1.6 % of the static load, where the fixed 30-span track, which the wheel
    /// crosses in that time, is within 0.02 % and 21 % (`docs/VALIDATION.md`).
    /// [`TrackWindow::CONVERGED`] takes the history's error to a third (0.53 %) for 1.5
    /// times the cost (8,958 instructions a step).
    pub const DEFAULT: TrackWindow = TrackWindow {
        ahead: 10.0,
        behind: 10.0,
        layer: 0.0,
        layer_rate: 0.0,
        exact_memory: 0.0,
    };
}

/// Grid nodes per sleeper span used by default: the converged choice of the grid
/// study in `docs/VALIDATION.md` (the thesis used 2).
pub const DEFAULT_NODES_PER_SPAN: usize = 8;
/// Default time step as a fraction of the critical step.
pub const DEFAULT_DT_FRACTION: f64 = 0.9;

/// km/h to m/s.
pub fn kmh(v: f64) -> f64 {
    v / 3.6
}

impl Scenario {
    /// Sets the grid (nodes per span) of a discrete track.
    pub fn set_nodes_per_span(&mut self, n: usize) {
        if let TrackSpec::Discrete(t) = &mut self.track {
            t.nodes_per_span = n;
        }
    }

    /// Sets how a discrete track's rail is taken under a wheel between grid nodes
    /// ([`RailBetweenNodes::Linear`] is the thesis' (3.23)).
    pub fn set_between_nodes(&mut self, b: RailBetweenNodes) {
        if let TrackSpec::Discrete(t) = &mut self.track {
            t.between_nodes = b;
        }
    }

    /// Sets how a discrete track's pads and ballast carry load
    /// ([`crate::track::SupportLaw::Linear`] is the thesis').
    pub fn set_supports(&mut self, supports: Supports) {
        if let TrackSpec::Discrete(t) = &mut self.track {
            t.supports = supports;
        }
    }

    /// Sets the number of spans of a discrete track.
    pub fn set_spans(&mut self, n: usize) {
        if let TrackSpec::Discrete(t) = &mut self.track {
            t.spans = n;
        }
    }
}

/// The side frames above the axle boxes with [`VehicleSpec::AxleBox`]: the track moves
/// them on from each input under the primary forces it computes
/// ([`crate::vehicle::PrimaryLink`]), so it needs their inertia.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SideFrameSpec {
    /// One side frame of `mass` (kg) over each wheelset's axle box on each side, in
    /// bounce (the roll-plane vehicle, `vehicle.sideframe.mass`).
    PerWheelset {
        /// Mass of one side frame (kg).
        mass: f64,
    },
    /// One side frame of `mass` (kg) and `pitch_inertia` (kg m^2) on each side over the
    /// first two wheelsets, in bounce and pitch (the half-car bogie: twice
    /// `vehicle.sideframe.mass`, `vehicle.sideframe.pitch_inertia`), its wheelbase the
    /// second wheelset's offset; with four wheelsets (the wagon) such side frames over
    /// wheelsets 3 and 4 too, at the same wheelbase. Needs two or four wheelsets.
    HalfCar {
        /// Mass of one side frame (kg).
        mass: f64,
        /// Pitch inertia of one side frame about its centre (kg m^2).
        pitch_inertia: f64,
        /// The bogies: 1, the half-car bogie's over wheelsets 1 and 2 (two wheelsets);
        /// 2, the wagon's over 1 and 2 and over 3 and 4 (four wheelsets).
        bogies: usize,
    },
    /// Nothing above the axle boxes ([`SideFrameInertia::NONE`]): the suspension's
    /// upper ends go on at the velocity they came in with (the two-axle wagon's car
    /// body). Needs the vehicle's wheelsets, the second at a wheelbase in its range.
    Nothing {
        /// The vehicle's wheelsets.
        wheelsets: usize,
        /// Its wheelbase range (m): `wheelset[2].offset`'s.
        wheelbase: (f64, f64),
        /// Its `vehicle.model` item, for the refusals.
        vehicle: &'static str,
    },
}

impl SideFrameSpec {
    /// The inertia at each axle box, and whether the first two wheelsets share their
    /// side frames, for the scenario `s`.
    ///
    /// Errors: a mass or pitch inertia outside its physical range (named as the FMU
    /// variables); the half-car's side frames without exactly two wheelsets, or with a
    /// wheelbase (`wheelset[2].offset`) outside 1 to 5 m.
    pub fn inertia(&self, s: &Scenario) -> crate::error::Result<(SideFrameInertia, bool)> {
        use crate::error::out_of_range;
        match *self {
            SideFrameSpec::Nothing {
                wheelsets,
                wheelbase: (lo, hi),
                vehicle,
            } => {
                let n = s.trailing.len() + 1;
                if n != wheelsets {
                    return Err(out_of_range(
                        "wheelsets",
                        n as f64,
                        format!("{wheelsets} with vehicle.model = {vehicle} at the axle boxes"),
                    ));
                }
                if let Some(w) = s.trailing.first()
                    && !(w.offset >= lo && w.offset <= hi)
                {
                    return Err(out_of_range(
                        "wheelset[2].offset",
                        w.offset,
                        format!(
                            "{lo} m <= wheelset[2].offset <= {hi} m (the wheelbase, with \
                             vehicle.model = {vehicle} at the axle boxes)"
                        ),
                    ));
                }
                Ok((SideFrameInertia::NONE, false))
            }
            SideFrameSpec::PerWheelset { mass } => {
                crate::limits::check("vehicle.sideframe.mass", mass)?;
                Ok((SideFrameInertia::single(mass), false))
            }
            SideFrameSpec::HalfCar {
                mass,
                pitch_inertia,
                bogies,
            } => {
                crate::limits::check("vehicle.sideframe.mass", 0.5 * mass)?;
                crate::limits::check("vehicle.sideframe.pitch_inertia", pitch_inertia)?;
                // Wheelsets 1 and 2 share side frames, and with four wheelsets (the
                // wagon's two bogies) wheelsets 3 and 4 too, at the same wheelbase.
                let n = s.trailing.len() + 1;
                if n != 2 * bogies {
                    return Err(out_of_range(
                        "wheelsets",
                        n as f64,
                        if bogies == 1 {
                            "2 with vehicle.model = half_car at the axle boxes (the bogie's side \
                             frames span wheelsets 1 and 2)"
                        } else {
                            "4 with vehicle.model = wagon at the axle boxes (the bogies' side \
                             frames span wheelsets 1 and 2, and 3 and 4)"
                        },
                    ));
                }
                let wheelbase = s.trailing[0].offset;
                crate::limits::check("vehicle.wheelbase", wheelbase).map_err(|e| {
                    e.renamed(
                        "vehicle.wheelbase",
                        "wheelset[2].offset",
                        "(the bogies' wheelbase, with vehicle.model = half_car or wagon at the \
                         axle boxes)",
                    )
                })?;
                if n == 4 {
                    let rear = s.trailing[2].offset - s.trailing[1].offset;
                    if (rear - wheelbase).abs() > 1e-9 * wheelbase {
                        return Err(out_of_range(
                            "wheelset[4].offset",
                            s.trailing[2].offset,
                            format!(
                                "wheelset[3].offset + the wheelbase wheelset[2].offset = {} m \
                                 (the rear bogie's wheelbase, with vehicle.model = wagon at the \
                                 axle boxes)",
                                crate::error::num(s.trailing[1].offset + wheelbase)
                            ),
                        ));
                    }
                }
                Ok((
                    SideFrameInertia::pitching(mass, pitch_inertia, wheelbase),
                    true,
                ))
            }
        }
    }
}
