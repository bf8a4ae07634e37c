//! The engine's parameters from the FMU variables (by value reference), one function
//! per engine struct.

use super::Kind;
use crate::contact::{ContactModel, ISO_3095_NAME, RoughnessSpectrum};
use crate::error::Error;
use crate::fmu::vars;
use crate::fmu::vars::enums::{
    contact_model, flat_shape, interface, rail_between_nodes, rails_correlation, support_law,
    track_spectrum,
};
use crate::fmu::vars::{
    FLAT_VRS, OFFSET_VRS, SITE_POSITION_VRS, STATIC_WHEEL_Z_VRS, TRAILING, TRAILING_FLAT_VRS,
    enums, vr,
};
use crate::numerics::Table;
use crate::sim::VehicleUnitParams;
use crate::sim::{
    RandomIrregularities, Roughness, Scenario, SideFrameSpec, TrackSpec, TrackWindow,
    TrailingWheelset, VehicleSpec, VoidedSleepers,
};
use crate::track::{
    ProfileSpec, RailBetweenNodes, RailDefect, RailEnds, RailProfile, RailSection, SupportLaw,
    Supports, TrackParams, TrackSpectrum,
};
use crate::vehicle::{AboveAxleBoxes, RollPlaneParams, VehicleKind, kind_of_item};
use crate::wheel::{FlatShape, FlatSpec, OutOfRoundness};
use std::io::Read;
use std::sync::Arc;

/// Track parameters (fixed rail ends).
pub fn track_params(v: &[f64]) -> TrackParams {
    let v = |r: u32| v[r as usize];
    TrackParams {
        spans: v(vr::TRACK_SPANS) as usize,
        nodes_per_span: v(vr::TRACK_NODES_PER_SPAN) as usize,
        sleeper_spacing: v(vr::TRACK_SLEEPER_SPACING),
        rail_seat_distance: v(vr::TRACK_RAIL_SEAT_DISTANCE),
        rail: RailSection {
            ei: v(vr::TRACK_RAIL_EI),
            kag: v(vr::TRACK_RAIL_KAG),
            mass: v(vr::TRACK_RAIL_MASS),
            rotary_inertia: v(vr::TRACK_RAIL_ROTARY_INERTIA),
        },
        pad_stiffness: v(vr::TRACK_PAD_STIFFNESS),
        pad_damping: v(vr::TRACK_PAD_DAMPING),
        ballast_stiffness: v(vr::TRACK_BALLAST_STIFFNESS),
        ballast_damping: v(vr::TRACK_BALLAST_DAMPING),
        sleeper_mass: v(vr::TRACK_SLEEPER_MASS),
        sleeper_inertia: v(vr::TRACK_SLEEPER_INERTIA),
        ends: RailEnds::Fixed,
        // The table's range holds the enumeration to its items (checked at set).
        between_nodes: match item(
            rail_between_nodes::Item::of,
            v(vr::TRACK_RAIL_BETWEEN_NODES),
        ) {
            rail_between_nodes::Item::Linear => RailBetweenNodes::Linear,
            rail_between_nodes::Item::Beam => RailBetweenNodes::Beam,
        },
        supports: Supports {
            law: match item(support_law::Item::of, v(vr::TRACK_SUPPORTS)) {
                support_law::Item::Tensionless => SupportLaw::Tensionless,
                support_law::Item::Linear => SupportLaw::Linear,
            },
            pad_preload: v(vr::TRACK_PAD_PRELOAD),
            ballast_preload: v(vr::TRACK_BALLAST_PRELOAD),
        },
    }
}

/// The item of an enumeration variable's value `value`, decoded by the table's
/// generated `of`: the FMI layer accepts only the items' values (its range, checked at
/// set), so a value without an item is a defect of the layer.
fn item<T>(of: fn(f64) -> Option<T>, value: f64) -> T {
    of(value).expect("the FMI layer holds an enumeration to its items")
}

/// The variables' values by name, for the vehicle registry
/// ([`crate::vehicle::VehicleKind::carrier`]).
fn by_name(v: &[f64]) -> impl Fn(&str) -> f64 + '_ {
    move |name| {
        // The registry names variables of the table (its test builds every kind from
        // its FMU's variables).
        let r = vars::vr_of(name).unwrap_or_else(|| panic!("{name} is no variable"));
        v[r as usize]
    }
}

/// Roll-plane vehicle parameters (table 4.4 by default).
pub fn vehicle_params(v: &[f64]) -> RollPlaneParams {
    crate::vehicle::roll_plane(&by_name(v))
}

/// The kind of vehicle `vehicle.model` names.
fn vehicle_model(v: &[f64]) -> &'static VehicleKind {
    // The table's range holds the enumeration to its items (checked at set), and the
    // registry's test gives every item a kind.
    enums::vehicle_model::item(v[vr::VEHICLE_MODEL as usize])
        .and_then(kind_of_item)
        .expect("vehicle.model is an item of the registry")
}

/// Whether the FMU couples at the axle boxes (`interface = axle_box`).
pub fn axle_box(v: &[f64]) -> bool {
    match item(interface::Item::of, v[vr::INTERFACE as usize]) {
        interface::Item::AxleBox => true,
        interface::Item::Contact => false,
    }
}

/// TrackContact's wheelset and primary suspension (`interface = axle_box`), in the
/// roll-plane vehicle's parameters: the bodies above it are the partner's (zero here,
/// unused).
pub fn wheelset_params(v: &[f64]) -> RollPlaneParams {
    let v = |r: u32| v[r as usize];
    RollPlaneParams::wheelset_on_primary(
        v(vr::VEHICLE_WHEELSET_MASS),
        v(vr::VEHICLE_WHEELSET_INERTIA),
        (
            v(vr::VEHICLE_PRIMARY_STIFFNESS),
            v(vr::VEHICLE_PRIMARY_DAMPING),
            v(vr::VEHICLE_PRIMARY_SPACING),
        ),
        v(vr::GRAVITY),
    )
}

/// The vehicle as a co-simulation unit (the own FMU of a kind of vehicle).
pub fn vehicle_unit_params(kind: Kind, v: &[f64]) -> VehicleUnitParams {
    let val = |r: u32| v[r as usize];
    let get = by_name(v);
    let model = kind
        .vehicle()
        .expect("the vehicle unit of a vehicle's FMU")
        .own_carrier(&get);
    let n = model.model().wheelsets();
    VehicleUnitParams {
        speed: val(vr::SPEED),
        wheel_radius: val(vr::WHEEL_RADIUS),
        dt: val(vr::SOLVER_DT),
        static_wheel_z: [val(vr::STATIC_WHEEL_Z_LEFT), val(vr::STATIC_WHEEL_Z_RIGHT)],
        axle_box: axle_box(v),
        model,
        // Only a vehicle on several wheelsets has the trailing wheelsets' (the others'
        // values are not theirs).
        trailing_static_wheel_z: std::array::from_fn(|k| {
            if k + 1 < n {
                STATIC_WHEEL_Z_VRS[k + 1].map(val)
            } else {
                [0.0; 2]
            }
        }),
    }
}

/// The flat whose variables (length, depth, angle, shape) have the value references
/// `f`; a length of 0 is no flat.
fn flat(v: &[f64], f: &[u32; 4]) -> FlatSpec {
    let val = |r: u32| v[r as usize];
    let depth = val(f[1]);
    FlatSpec {
        length: val(f[0]),
        depth: if depth == 0.0 { None } else { Some(depth) },
        angle: val(f[2]),
        shape: match item(flat_shape::Item::of, val(f[3])) {
            flat_shape::Item::Chord => FlatShape::Chord,
            flat_shape::Item::Haversine => FlatShape::Haversine,
        },
    }
}

/// The scenario the variables of a track-carrying FMU describe: CoupledSystem carries
/// the roll-plane vehicle or the half-car bogie (its wheelbase `wheelset[2].offset`),
/// TrackContact external wheels with the given static loads.
pub fn scenario(kind: Kind, v: &[f64]) -> Scenario {
    let val = |r: u32| v[r as usize];
    let flats_of = |vrs: &[[[u32; 4]; 4]; 2]| {
        [0, 1].map(|side| vrs[side].iter().map(|f| flat(v, f)).collect::<Vec<_>>())
    };
    let flats = flats_of(&FLAT_VRS);
    let wheelsets = val(vr::WHEELSETS) as usize;
    let trailing = (0..wheelsets.saturating_sub(1).min(TRAILING))
        .map(|k| TrailingWheelset {
            offset: val(OFFSET_VRS[k]),
            flats: flats_of(&TRAILING_FLAT_VRS[k]),
            roundness: Default::default(),
        })
        .collect();
    let sites = SITE_POSITION_VRS[..(val(vr::SITES) as usize).min(SITE_POSITION_VRS.len())]
        .iter()
        .map(|&r| val(r))
        .collect();
    let static_load = [val(vr::STATIC_LOAD_LEFT), val(vr::STATIC_LOAD_RIGHT)];
    let model = vehicle_model(v);
    let offsets: Vec<f64> = OFFSET_VRS.iter().map(|&r| val(r)).collect();
    let vehicle = match kind {
        Kind::CoupledSystem => VehicleSpec::of_kind((model.carrier)(&by_name(v), &offsets)),
        _ if axle_box(v) => VehicleSpec::AxleBox {
            vehicle: wheelset_params(v),
            side_frames: match model.above_axle_boxes {
                AboveAxleBoxes::SideFramePerWheelset => SideFrameSpec::PerWheelset {
                    mass: val(vr::VEHICLE_SIDEFRAME_MASS),
                },
                AboveAxleBoxes::BogieSideFrames { bogies } => SideFrameSpec::HalfCar {
                    mass: 2.0 * val(vr::VEHICLE_SIDEFRAME_MASS),
                    pitch_inertia: val(vr::VEHICLE_SIDEFRAME_PITCH_INERTIA),
                    bogies,
                },
                AboveAxleBoxes::Nothing { wheelbase } => SideFrameSpec::Nothing {
                    wheelsets: model.wheelsets,
                    wheelbase,
                    vehicle: model.item,
                },
            },
            static_load,
        },
        _ => VehicleSpec::External { static_load },
    };
    Scenario {
        name: kind.table().model_identifier.into(),
        track: TrackSpec::Discrete(track_params(v)),
        vehicle,
        wheel_radius: val(vr::WHEEL_RADIUS),
        flats,
        // The table's range holds the enumeration to its items (checked at set).
        contact_model: match item(contact_model::Item::of, val(vr::CONTACT_MODEL)) {
            contact_model::Item::Hertz => ContactModel::Hertz,
            contact_model::Item::Adaptive => ContactModel::Adaptive,
        },
        kw: val(vr::CONTACT_KW),
        hertz_coefficient: val(vr::CONTACT_CH),
        speed: val(vr::SPEED),
        start_position: val(vr::START_POSITION),
        dt: val(vr::SOLVER_DT),
        sites,
        trailing,
        window: (val(vr::TRACK_WINDOW_AHEAD) > 0.0).then(|| TrackWindow {
            ahead: val(vr::TRACK_WINDOW_AHEAD),
            behind: val(vr::TRACK_WINDOW_BEHIND),
            ..TrackWindow::DEFAULT
        }),
        voids: (val(vr::TRACK_VOID_SLEEPERS) > 0.0).then(|| VoidedSleepers {
            position: val(vr::TRACK_VOID_POSITION),
            sleepers: val(vr::TRACK_VOID_SLEEPERS) as usize,
            gap: val(vr::TRACK_VOID_GAP),
        }),
        rails: [vr::RAIL_DEFECT_LEFT_DEPTH, vr::RAIL_DEFECT_RIGHT_DEPTH].map(|depth| RailProfile {
            measured: None,
            defect: (val(depth) > 0.0).then(|| RailDefect {
                position: val(vr::RAIL_DEFECT_POSITION),
                length: val(vr::RAIL_DEFECT_LENGTH),
                depth: val(depth),
            }),
            random: None,
        }),
        roundness: Default::default(),
        random: RandomIrregularities {
            profile: track_spectrum(val(vr::RAIL_SPECTRUM)).map(|spectrum| ProfileSpec {
                spectrum,
                seed: val(vr::RAIL_SPECTRUM_SEED) as u64,
                band: (
                    val(vr::RAIL_SPECTRUM_SHORTEST_WAVELENGTH),
                    val(vr::RAIL_SPECTRUM_LONGEST_WAVELENGTH),
                ),
                cross_level: item(rails_correlation::Item::of, val(vr::RAIL_SPECTRUM_RAILS))
                    == rails_correlation::Item::CrossLevel,
                ramp: val(vr::RAIL_SPECTRUM_RAMP),
            }),
            // The spectra are String parameters: `with_tables` gives them.
            roughness: Some(Roughness {
                rail: None,
                wheel: None,
                seed: val(vr::ROUGHNESS_SEED) as u64,
                patch_length: val(vr::ROUGHNESS_PATCH_LENGTH),
            }),
        },
    }
}

/// The spectrum `rail.spectrum`'s value names; `None` for `none`.
fn track_spectrum(value: f64) -> Option<TrackSpectrum> {
    use track_spectrum::Item;
    Some(match item(Item::of, value) {
        Item::None => return None,
        Item::FraClass1 => TrackSpectrum::Fra(1),
        Item::FraClass2 => TrackSpectrum::Fra(2),
        Item::FraClass3 => TrackSpectrum::Fra(3),
        Item::FraClass4 => TrackSpectrum::Fra(4),
        Item::FraClass5 => TrackSpectrum::Fra(5),
        Item::FraClass6 => TrackSpectrum::Fra(6),
        Item::OreLow => TrackSpectrum::OreLow,
        Item::OreHigh => TrackSpectrum::OreHigh,
    })
}

/// The largest table file read (bytes): a million points of two numbers in full
/// precision with comments to spare.
pub const MAX_TABLE_FILE: u64 = 100_000_000;

/// The content of the table a String parameter `name` gives in `text`: empty for an
/// empty text (no table), the text itself when it holds a `;` or a line break (`0 0;
/// 0.1 2e-5; ...`), else the text of the file at that path (absolute, or relative to
/// the working directory of the process that loaded the FMU), read now, once.
///
/// Errors: a file that cannot be read, is not a regular file or is too large, naming
/// `name` and the path; nothing of the file is quoted.
pub fn table_content(name: &str, text: &str) -> Result<Arc<str>, Error> {
    let text = text.trim();
    if text.is_empty()
        || text.contains(';')
        || text.contains('\n')
        || (name.starts_with("roughness.") && text == ISO_3095_NAME)
    {
        return Ok(Arc::from(text));
    }
    // A roughness spectrum may also be named (`iso3095`, as written: lower case).
    let named = if name.starts_with("roughness.") {
        format!(", or {ISO_3095_NAME} (the ISO 3095 limit)")
    } else {
        String::new()
    };
    let refuse = |why: String| {
        Error::Table(format!(
            "{name} = {text:?}: {why}; give a path (absolute, or relative to the working \
             directory) or the table itself (`x y; x y; ...`){named}"
        ))
    };
    // A regular file of at most MAX_TABLE_FILE bytes: not a directory, a device or a
    // pipe, which could block or never end.
    let meta = std::fs::metadata(text)
        .map_err(|e| refuse(format!("cannot read the table's file ({e})")))?;
    if !meta.is_file() {
        return Err(refuse("not a regular file".into()));
    }
    let too_large = || {
        refuse(format!(
            "the file has more than {MAX_TABLE_FILE} bytes; a table's file holds at most \
             {MAX_TABLE_FILE} (1,000,000 points)"
        ))
    };
    if meta.len() > MAX_TABLE_FILE {
        return Err(too_large());
    }
    // Read at most a word past the limit (files such as /proc/self/pagemap read whole
    // words only): a file's stated size may be 0 (/proc) or out of date (a file still
    // growing), and it is never read further (issue 38).
    let mut bytes = Vec::new();
    std::fs::File::open(text)
        .and_then(|f| f.take(MAX_TABLE_FILE + 8).read_to_end(&mut bytes))
        .map_err(|e| refuse(format!("cannot read the table's file ({e})")))?;
    if bytes.len() as u64 > MAX_TABLE_FILE {
        return Err(too_large());
    }
    let content =
        String::from_utf8(bytes).map_err(|_| refuse("the file is not UTF-8 text".into()))?;
    Ok(Arc::from(content))
}

/// The table in `content` ([`table_content`]): none when empty, else read by
/// [`Table::parse`]; `name` names it in errors.
pub fn parse_table(name: &str, content: &str) -> Result<Option<Table>, Error> {
    if content.trim().is_empty() {
        return Ok(None);
    }
    Table::parse(content, name).map(Some)
}

/// Reads the String parameter `name`'s value `text` as the model will ([`table_content`])
/// and checks the table: a rail profile's heights and steepness, a wheel's
/// out-of-roundness angles and deviations (its steepness needs the wheel radius: the
/// scenario's check). Gives the content the model is built from.
pub fn check_table(name: &str, text: &str) -> Result<Arc<str>, Error> {
    let content = table_content(name, text)?;
    let label = if content.as_ref() == text.trim() {
        name.to_string()
    } else {
        format!("{name} (the file {})", text.trim())
    };
    if name.starts_with("roughness.") {
        if !content.trim().is_empty() {
            RoughnessSpectrum::parse(&content, &label)?;
        }
        return Ok(content);
    }
    match parse_table(&label, &content)? {
        None => {}
        Some(t) if name.ends_with(".out_of_roundness") => {
            OutOfRoundness::new(t, &label)?;
        }
        Some(t) => RailProfile::check_measured(&t, &label)?,
    }
    Ok(content)
}

/// `s` with the tables the String parameters' `contents` (by value reference,
/// [`check_table`]) hold: the rails' measured profiles and the wheels' out-of-roundness.
pub fn with_tables(mut s: Scenario, contents: &[Arc<str>]) -> Result<Scenario, Error> {
    let text = |name: &str| -> &str {
        crate::fmu::vars::COUPLED_SYSTEM
            .vars
            .iter()
            .find(|v| v.name == name)
            .map_or("", |v| &contents[v.vr as usize])
    };
    let wheel = |name: String| -> Result<Option<Arc<OutOfRoundness>>, Error> {
        match parse_table(&name, text(&name))? {
            None => Ok(None),
            Some(t) => Ok(Some(Arc::new(OutOfRoundness::new(t, &name)?))),
        }
    };
    for (side, rail) in ["left", "right"].iter().zip(&mut s.rails) {
        let name = format!("rail.{side}.profile");
        // Checked by `Scenario::validate`, which `Simulation::new` calls first.
        if let Some(t) = parse_table(&name, text(&name))? {
            rail.measured = Some(Arc::new(t));
        }
    }
    if let Some(r) = &mut s.random.roughness {
        let spectrum = |name: &str| -> Result<Option<Arc<RoughnessSpectrum>>, Error> {
            let t = text(name);
            if t.trim().is_empty() {
                return Ok(None);
            }
            Ok(Some(Arc::new(RoughnessSpectrum::parse(t, name)?)))
        };
        r.rail = spectrum("roughness.rail")?;
        r.wheel = spectrum("roughness.wheel")?;
        if r.rail.is_none() && r.wheel.is_none() {
            s.random.roughness = None;
        }
    }
    for (i, side) in ["left", "right"].iter().enumerate() {
        s.roundness[i] = wheel(format!("wheel.{side}.out_of_roundness"))?;
        for (k, w) in s.trailing.iter_mut().enumerate() {
            w.roundness[i] = wheel(format!("wheelset[{}].wheel.{side}.out_of_roundness", k + 2))?;
        }
    }
    Ok(s)
}
