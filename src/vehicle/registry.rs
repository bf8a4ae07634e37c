//! The vehicle registry: every kind of vehicle, once. Each entry gives its item of the
//! table's `VehicleModel` enumeration (`vehicle.model`), its own FMU, its wheelsets,
//! what TrackContact carries above its axle boxes at the axle-box interface, and how
//! its parameters come from the FMU variables (by name). Everything that works out the
//! kind reads it: the FMU binding (which FMU an instance is, its parameters), the
//! scenario (CoupledSystem's and TrackContact's `vehicle.model`), the static start, the
//! packer's system files, the Python helpers (through the generated `vehicles.json`)
//! and the tests that keep the prose's list of FMUs equal to it.
//!
//! A new vehicle kind: its model in a file of this folder (a [`super::LinearVehicle`]
//! gives the stepping, [`CarrierModel`] what the assembly needs), one item of
//! [`CarrierSpec`], one entry of [`VEHICLE_KINDS`], and in the table its `<Fmu>`
//! element, its `VehicleModel` item and its name in the groups it belongs to.

use super::rail_vehicle::CarrierModel;
use super::{HalfCarParams, RollPlaneParams, TwoAxleParams, WagonParams};

/// The parameters of a vehicle on several wheelsets, of any kind the registry lists.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CarrierSpec {
    /// The roll-plane vehicle ([`RollPlaneParams`]), on one wheelset.
    RollPlane(RollPlaneParams),
    /// The half-car bogie ([`HalfCarParams`]).
    HalfCar(HalfCarParams),
    /// The four-axle wagon ([`WagonParams`]).
    Wagon(WagonParams),
    /// The two-axle wagon ([`TwoAxleParams`]).
    TwoAxle(TwoAxleParams),
}

impl CarrierSpec {
    /// The vehicle behind its interface.
    pub fn model(&self) -> &dyn CarrierModel {
        match self {
            CarrierSpec::RollPlane(p) => p,
            CarrierSpec::HalfCar(p) => p,
            CarrierSpec::Wagon(p) => p,
            CarrierSpec::TwoAxle(p) => p,
        }
    }
}

/// What TrackContact carries above a kind's axle boxes at the axle-box interface
/// (`interface = axle_box`), moving it on over each communication step
/// ([`super::PrimaryLink`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AboveAxleBoxes {
    /// A side frame of `vehicle.sideframe.mass` over each wheelset's axle box, in
    /// bounce (the roll-plane vehicle).
    SideFramePerWheelset,
    /// Pitching side frames (twice `vehicle.sideframe.mass`,
    /// `vehicle.sideframe.pitch_inertia`) over each pair of wheelsets, one pair per
    /// bogie (the half-car bogie: 1, the wagon: 2).
    BogieSideFrames {
        /// Bogies.
        bogies: usize,
    },
    /// Nothing: the suspension's upper ends go on at the velocity they came in with
    /// ([`super::SideFrameInertia::NONE`]; the two-axle wagon's car body), the wheelsets
    /// `wheelbase` (m, least and largest) apart.
    Nothing {
        /// The vehicle's wheelbase range (m).
        wheelbase: (f64, f64),
    },
}

/// The parameter values by variable name (as the FMUs name them).
pub type Values<'a> = &'a dyn Fn(&str) -> f64;

/// One kind of vehicle.
#[derive(Debug, Clone, Copy)]
pub struct VehicleKind {
    /// Its item of the table's `VehicleModel` enumeration (`vehicle.model`).
    pub item: &'static str,
    /// The model identifier of its own FMU.
    pub fmu: &'static str,
    /// Wheelsets it rests on.
    pub wheelsets: usize,
    /// What TrackContact carries above its axle boxes.
    pub above_axle_boxes: AboveAxleBoxes,
    /// Where its own FMU places the wheelsets behind the leading one: each offset the
    /// sum of these parameters of its FMU (the wagon's fourth wheelset: the bogie
    /// distance plus the wheelbase).
    pub offsets: &'static [&'static [&'static str]],
    /// Its parameters from the variables, its wheelsets behind the leading one at
    /// `offsets` (m): CoupledSystem's `wheelset[k].offset`, or in its own FMU those of
    /// [`VehicleKind::offsets`].
    pub carrier: fn(Values, &[f64]) -> CarrierSpec,
}

impl VehicleKind {
    /// The offsets (m) of the wheelsets behind the leading one that the parameters `v`
    /// of its own FMU give ([`VehicleKind::offsets`]).
    pub fn own_offsets(&self, v: Values) -> Vec<f64> {
        self.offsets
            .iter()
            .map(|names| names.iter().map(|n| v(n)).sum())
            .collect()
    }

    /// The vehicle its own FMU's parameters `v` describe.
    pub fn own_carrier(&self, v: Values) -> CarrierSpec {
        (self.carrier)(v, &self.own_offsets(v))
    }
}

/// Every kind of vehicle, the roll-plane vehicle first.
pub const VEHICLE_KINDS: [VehicleKind; 4] = [
    VehicleKind {
        item: "roll_plane",
        fmu: "RollPlaneVehicle",
        wheelsets: 1,
        above_axle_boxes: AboveAxleBoxes::SideFramePerWheelset,
        offsets: &[],
        carrier: |v, _| CarrierSpec::RollPlane(roll_plane(v)),
    },
    VehicleKind {
        item: "half_car",
        fmu: "HalfCarBogie",
        wheelsets: 2,
        above_axle_boxes: AboveAxleBoxes::BogieSideFrames { bogies: 1 },
        offsets: &[&["vehicle.wheelbase"]],
        carrier: |v, offsets| CarrierSpec::HalfCar(half_car(v, offsets[0])),
    },
    VehicleKind {
        item: "wagon",
        fmu: "Wagon",
        wheelsets: 4,
        above_axle_boxes: AboveAxleBoxes::BogieSideFrames { bogies: 2 },
        offsets: &[
            &["vehicle.wheelbase"],
            &["vehicle.bogie_distance"],
            &["vehicle.bogie_distance", "vehicle.wheelbase"],
        ],
        // The wheelbase and the bogie distance are the offsets of wheelsets 2 and 3
        // (the engine checks the fourth).
        carrier: |v, offsets| {
            let (a, d) = (offsets[0], offsets[1]);
            CarrierSpec::Wagon(WagonParams {
                carbody_mass: 4.0 * v("vehicle.carbody_mass"),
                carbody_pitch_inertia: v("vehicle.carbody.pitch_inertia"),
                carbody_roll_inertia: v("vehicle.carbody.roll_inertia"),
                bogie_distance: d,
                bogie: half_car(v, a),
            })
        },
    },
    VehicleKind {
        item: "two_axle",
        fmu: "TwoAxleWagon",
        wheelsets: 2,
        above_axle_boxes: AboveAxleBoxes::Nothing {
            wheelbase: super::two_axle::WHEELBASE_RANGE,
        },
        offsets: &[&["wheelset[2].offset"]],
        carrier: |v, offsets| {
            // The car body twice the car-body share per wheelset, the four-axle
            // wagon's body halved (docs/MODEL.md, The two-axle wagon).
            CarrierSpec::TwoAxle(TwoAxleParams {
                carbody_mass: 2.0 * v("vehicle.carbody_mass"),
                carbody_pitch_inertia: 0.5 * v("vehicle.carbody.pitch_inertia"),
                carbody_roll_inertia: 0.5 * v("vehicle.carbody.roll_inertia"),
                wheelset_mass: v("vehicle.wheelset.mass"),
                wheelset_inertia: v("vehicle.wheelset.inertia"),
                stiffness: v("vehicle.primary.stiffness"),
                damping: v("vehicle.primary.damping"),
                spacing: v("vehicle.primary.spacing"),
                wheelbase: offsets[0],
                gravity: v("gravity"),
            })
        },
    },
];

/// The kind whose `VehicleModel` item is `item`.
pub fn kind_of_item(item: &str) -> Option<&'static VehicleKind> {
    VEHICLE_KINDS.iter().find(|k| k.item == item)
}

/// The kind whose own FMU is `fmu`.
pub fn kind_of_fmu(fmu: &str) -> Option<&'static VehicleKind> {
    VEHICLE_KINDS.iter().find(|k| k.fmu == fmu)
}

/// The roll-plane vehicle's parameters (table 4.4 by default) from the variables.
pub fn roll_plane(v: Values) -> RollPlaneParams {
    RollPlaneParams {
        carbody_mass: v("vehicle.carbody_mass"),
        bolster_mass: v("vehicle.bolster.mass"),
        bolster_inertia: v("vehicle.bolster.inertia"),
        sideframe_mass: v("vehicle.sideframe.mass"),
        wheelset_mass: v("vehicle.wheelset.mass"),
        wheelset_inertia: v("vehicle.wheelset.inertia"),
        primary_stiffness: v("vehicle.primary.stiffness"),
        primary_damping: v("vehicle.primary.damping"),
        primary_spacing: v("vehicle.primary.spacing"),
        secondary_stiffness: v("vehicle.secondary.stiffness"),
        secondary_damping: v("vehicle.secondary.damping"),
        secondary_spacing: v("vehicle.secondary.spacing"),
        gravity: v("gravity"),
    }
}

/// The half-car bogie of the roll-plane vehicle's parameters (half a bogie) with the
/// wheelbase `a` (m) and the side frames' pitch inertia of the variables.
fn half_car(v: Values, a: f64) -> HalfCarParams {
    HalfCarParams::from_roll_plane(&roll_plane(v), a, v("vehicle.sideframe.pitch_inertia"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each entry's parameters build a vehicle on as many wheelsets as the entry says,
    /// at as many offsets, from the table's start values.
    #[test]
    fn each_kind_builds_its_vehicle_from_the_table() {
        use crate::fmu::vars;
        for k in &VEHICLE_KINDS {
            let table = vars::fmu_table(k.fmu).expect("the kind's FMU is in the table");
            let start = |name: &str| {
                let vr = vars::vr_of(name).unwrap_or_else(|| panic!("{name} in the table"));
                table
                    .vars
                    .iter()
                    .find(|s| s.vr == vr)
                    .map(|s| s.start)
                    .unwrap_or_else(|| panic!("{}: {name} is a variable of it", k.fmu))
            };
            assert!(
                vars::enums::vehicle_model::ITEMS
                    .iter()
                    .any(|(n, _)| *n == k.item),
                "{} is an item of VehicleModel",
                k.item
            );
            assert_eq!(k.offsets.len(), k.wheelsets - 1, "{}", k.fmu);
            // The wheelbase range the track checks at the axle boxes is the one the
            // kind's FMU declares for its wheelbase.
            if let AboveAxleBoxes::Nothing { wheelbase } = k.above_axle_boxes {
                let vr = vars::vr_of(k.offsets[0][0]).expect("a variable");
                let s = table.vars.iter().find(|s| s.vr == vr).expect("of the FMU");
                assert_eq!((s.min, s.max), wheelbase, "{}", k.fmu);
            }
            let c = k.own_carrier(&start);
            let m = c.model();
            assert_eq!(m.wheelsets(), k.wheelsets, "{}", k.fmu);
            assert_eq!(m.offsets().len(), k.wheelsets - 1, "{}", k.fmu);
            m.validate().unwrap();
        }
        // And every item of the enumeration is a kind.
        for (item, _) in vars::enums::vehicle_model::ITEMS {
            assert!(kind_of_item(item).is_some(), "{item} has no registry entry");
        }
    }
}
