//! The thesis' parameter sets as ready-made scenarios, with its misprints handled as
//! `docs/MODEL.md` says:
//!
//! * Table 5.1 car body mass reads 1470.2 kg; 14702 kg gives the 82 kN static wheel
//!   load used elsewhere for the same vehicle, so 14702 kg is used.
//! * Pad damping "45 kN/m" (tables 4.1, 4.4) and "15 kN/m" (5.2) are kN s/m.
//! * Section 4.2.1's time step "0.00045 s" is 0.000045 s (table 4.2).
//! * Table 5.2's radial spring stiffness 3.5574e9 N/m/rad is ten times below every
//!   other table and below what (2.25) gives for a usual Hertz coefficient
//!   (it implies C_H ~ 1.0e10 N/m^1.5); the printed value is kept.

use super::scenario::{
    DEFAULT_NODES_PER_SPAN, Scenario, TrackSpec, TrackWindow, TrailingWheelset, VehicleSpec, kmh,
};
use crate::contact::ContactModel;
use crate::track::{RailBetweenNodes, RailEnds, RailSection, Supports, TrackParams};
use crate::vehicle::{
    CarrierSpec, LumpedTrackParams, LumpedWheelParams, RollPlaneParams, WagonParams,
};
use crate::wheel::FlatSpec;

/// The track of tables 4.1 and 4.4 with `spans` sleeper spans at the default grid.
fn table_4_track(spans: usize) -> TrackParams {
    TrackParams {
        spans,
        nodes_per_span: DEFAULT_NODES_PER_SPAN,
        sleeper_spacing: 0.685,
        rail_seat_distance: 1.505,
        rail: RailSection::from_material(2.07e11, 81e9, 7.77e-3, 2.94e-5, 0.34, 60.0)
            .expect("table 4.4 rail"),
        pad_stiffness: 140e6,
        pad_damping: 45e3, // printed "45 kN/m": kN s/m
        ballast_stiffness: 40e6,
        ballast_damping: 50e3,
        sleeper_mass: 270.0,
        sleeper_inertia: 90.0,
        ends: RailEnds::Fixed,
        between_nodes: RailBetweenNodes::Beam,
        supports: Supports::default(),
    }
}

impl Scenario {
    /// Table 4.4 (vehicle and track of chapters 4-5), perfect wheels, 70 km/h, 30 spans,
    /// `K_w = 3.3443e10` N/m/rad, `R_w = 0.475` m, start 2 spans from the left end.
    pub fn table_4_4() -> Scenario {
        Scenario {
            name: "table 4.4".into(),
            track: TrackSpec::Discrete(table_4_track(30)),
            vehicle: VehicleSpec::RollPlane(RollPlaneParams {
                carbody_mass: 20150.0,
                bolster_mass: 232.5,
                bolster_inertia: 87.5,
                sideframe_mass: 223.75,
                wheelset_mass: 1120.0,
                wheelset_inertia: 420.1,
                primary_stiffness: 6.5e6,
                primary_damping: 100e3,
                primary_spacing: 1.6002,
                secondary_stiffness: 2.55e6,
                secondary_damping: 44.24e3,
                secondary_spacing: 1.6002,
                gravity: 9.81,
            }),
            wheel_radius: 0.475,
            flats: [Vec::new(), Vec::new()],
            contact_model: ContactModel::Adaptive,
            kw: 3.3443e10,
            hertz_coefficient: 0.85e11,
            speed: kmh(70.0),
            start_position: 2.0 * 0.685,
            dt: 0.0,
            sites: Vec::new(),
            trailing: Vec::new(),
            window: None,
            voids: None,
            rails: Default::default(),
            roundness: Default::default(),
            random: Default::default(),
        }
    }

    /// The reference case: table 4.4, 70 km/h, a 100 mm x 1.5 mm haversine flat
    /// on the left wheel whose centre starts 90 degrees ahead of the contact point.
    pub fn table_4_4_flat() -> Scenario {
        let mut s = Scenario::table_4_4();
        s.name = "table 4.4, 100 mm x 1.5 mm flat on the left wheel".into();
        s.flats[0].push(FlatSpec::haversine(
            0.1,
            0.0015,
            std::f64::consts::FRAC_PI_2,
        ));
        s
    }

    /// The four-axle wagon of table 4.4 (`WagonParams::table_4_4`: bogie centres 10 m
    /// apart, 1.8 m wheelbases, side frames of 180 kg m^2 in pitch) on wheelsets 0, 1.8,
    /// 10 and 11.8 m behind the leading one, the reference flat on the leading left
    /// wheel, 70 km/h, on the endless track's converged window (issue 28's case).
    pub fn table_4_4_wagon() -> Scenario {
        let mut s = Scenario::table_4_4_flat();
        s.name = "table 4.4 wagon, 100 mm x 1.5 mm flat on the leading left wheel".into();
        let VehicleSpec::RollPlane(p) = s.vehicle else {
            unreachable!("table 4.4 has the roll-plane vehicle")
        };
        s.vehicle = VehicleSpec::Carrier(CarrierSpec::Wagon(WagonParams::table_4_4(
            &p, 10.0, 1.8, 180.0,
        )));
        s.trailing = [1.8, 10.0, 11.8]
            .map(|offset| TrailingWheelset {
                offset,
                ..Default::default()
            })
            .to_vec();
        s.window = Some(TrackWindow::CONVERGED);
        s
    }

    /// Table 4.1 track (20 spans) under a constant 100 kN per rail at 50 km/h (section 4.2.1).
    pub fn table_4_1() -> Scenario {
        let mut s = Scenario::table_4_4();
        s.name = "table 4.1, constant 100 kN per rail".into();
        s.track = TrackSpec::Discrete(table_4_track(20));
        s.vehicle = VehicleSpec::ConstantLoad([100e3, 100e3]);
        s.kw = 5.3361e10;
        s.speed = kmh(50.0);
        s.start_position = 0.685;
        s
    }

    /// Table 5.1 (Canadian Pacific, after Dong), car body 14702 kg (misprint 1470.2),
    /// `R_w = 0.4572` m, `K_w = 5.3787e10`, 100 km/h.
    pub fn table_5_1() -> Scenario {
        Scenario {
            name: "table 5.1".into(),
            track: TrackSpec::Discrete(TrackParams {
                spans: 30,
                nodes_per_span: DEFAULT_NODES_PER_SPAN,
                sleeper_spacing: 0.6069,
                rail_seat_distance: 1.505,
                rail: RailSection::from_material(2.07e11, 81e9, 8.61e-3, 3.95e-5, 0.34, 67.57)
                    .expect("table 5.1 rail"),
                pad_stiffness: 200e6,
                pad_damping: 30e3,
                ballast_stiffness: 40e6,
                ballast_damping: 50e3,
                sleeper_mass: 180.0,
                sleeper_inertia: 90.0,
                ends: RailEnds::Fixed,
                between_nodes: RailBetweenNodes::Beam,
                supports: Supports::default(),
            }),
            vehicle: VehicleSpec::RollPlane(RollPlaneParams {
                carbody_mass: 14702.0,
                bolster_mass: 232.5,
                bolster_inertia: 87.5,
                sideframe_mass: 250.0,
                wheelset_mass: 1300.0,
                wheelset_inertia: 500.0,
                primary_stiffness: 788e6,
                primary_damping: 3.5e3,
                primary_spacing: 1.6002,
                secondary_stiffness: 6.11e6,
                secondary_damping: 158e3,
                secondary_spacing: 1.6002,
                gravity: 9.81,
            }),
            wheel_radius: 0.4572,
            flats: [Vec::new(), Vec::new()],
            contact_model: ContactModel::Adaptive,
            kw: 5.3787e10,
            hertz_coefficient: 0.85e11,
            speed: kmh(100.0),
            start_position: 2.0 * 0.6069,
            dt: 0.0,
            sites: Vec::new(),
            trailing: Vec::new(),
            window: None,
            voids: None,
            rails: Default::default(),
            roundness: Default::default(),
            random: Default::default(),
        }
    }

    /// Table 5.2 (CHARMEC field test), UIC60 rail as EI, kAG, m r^2; `R_w = 0.45` m;
    /// `K_w = 3.5574e9` as printed (see the module notes); 50 km/h, 100 mm x 0.9 mm flat.
    pub fn table_5_2() -> Scenario {
        let mut s = Scenario::table_5_1();
        s.name = "table 5.2 (field test), 100 mm x 0.9 mm flat".into();
        s.track = TrackSpec::Discrete(TrackParams {
            spans: 30,
            nodes_per_span: DEFAULT_NODES_PER_SPAN,
            sleeper_spacing: 0.65,
            rail_seat_distance: 1.505,
            rail: RailSection {
                ei: 6.4e6,
                kag: 250e6,
                mass: 60.0,
                rotary_inertia: 0.24,
            },
            pad_stiffness: 80e6,
            pad_damping: 15e3, // printed "15 kN/m": kN s/m
            ballast_stiffness: 30e6,
            ballast_damping: 31e3,
            sleeper_mass: 250.0,
            sleeper_inertia: 90.0,
            ends: RailEnds::Fixed,
            between_nodes: RailBetweenNodes::Beam,
            supports: Supports::default(),
        });
        s.vehicle = VehicleSpec::RollPlane(RollPlaneParams {
            carbody_mass: 22135.0,
            bolster_mass: 232.5,
            bolster_inertia: 87.5,
            sideframe_mass: 223.75,
            wheelset_mass: 1185.0,
            wheelset_inertia: 420.1,
            primary_stiffness: 788e6,
            primary_damping: 3.5e3,
            primary_spacing: 1.6002,
            secondary_stiffness: 6.11e6,
            secondary_damping: 15.8e3,
            secondary_spacing: 1.6002,
            gravity: 9.81,
        });
        s.wheel_radius = 0.45;
        s.kw = 3.5574e9;
        s.speed = kmh(50.0);
        s.start_position = 2.0 * 0.65;
        s.flats[0].push(FlatSpec::haversine(
            0.1,
            0.0009,
            std::f64::consts::FRAC_PI_2,
        ));
        s
    }

    /// Chapter 2 lumped model (section 2.4.2): 82 kN wheel load, `R_w = 0.4572` m,
    /// half wheelset 325 kg on primary (788 MN/m, 3.5 kN s/m) and secondary
    /// (6.11 MN/m, 158 kN s/m) suspensions in series; track mass of 1.5 spans of
    /// 67.57 kg/m rail at 0.65 m on 33.3 MN/m and 80 kN s/m; `K_w` from
    /// `C_H = 0.87e11` N/m^1.5 and the static load (fig. 2.10); a 100 mm x 1.5 mm
    /// haversine flat starting at 90 degrees; 50 km/h.
    pub fn chapter_2() -> Scenario {
        let series = |a: f64, b: f64| a * b / (a + b);
        Scenario {
            name: "chapter 2 lumped model".into(),
            track: TrackSpec::Lumped(LumpedTrackParams {
                mass: 67.57 * 0.65 * 1.5,
                stiffness: 33.3e6,
                damping: 80e3,
            }),
            vehicle: VehicleSpec::LumpedWheels(LumpedWheelParams {
                mass: 325.0,
                stiffness: series(788e6, 6.11e6),
                damping: series(3.5e3, 158e3),
                load: 82e3,
            }),
            wheel_radius: 0.4572,
            flats: [
                vec![FlatSpec::haversine(
                    0.1,
                    0.0015,
                    std::f64::consts::FRAC_PI_2,
                )],
                Vec::new(),
            ],
            contact_model: ContactModel::Adaptive,
            kw: 0.0,
            hertz_coefficient: 0.87e11,
            speed: kmh(50.0),
            start_position: 0.0,
            dt: 1e-6,
            sites: Vec::new(),
            trailing: Vec::new(),
            window: None,
            voids: None,
            rails: Default::default(),
            roundness: Default::default(),
            random: Default::default(),
        }
    }

    /// Looks a preset up by name: `table4.4`, `table4.4-flat`, `table4.1`, `table5.1`,
    /// `table5.2`, `chapter2`.
    pub fn preset(name: &str) -> Option<Scenario> {
        Some(match name {
            "table4.4" => Scenario::table_4_4(),
            "table4.4-flat" => Scenario::table_4_4_flat(),
            "table4.1" => Scenario::table_4_1(),
            "table5.1" => Scenario::table_5_1(),
            "table5.2" => Scenario::table_5_2(),
            "chapter2" => Scenario::chapter_2(),
            _ => return None,
        })
    }

    /// Names accepted by [`Scenario::preset`].
    pub const PRESETS: [&'static str; 6] = [
        "table4.4",
        "table4.4-flat",
        "table4.1",
        "table5.1",
        "table5.2",
        "chapter2",
    ];
}
