//! Command-line runner: simulate a parameter set and write the time histories as CSV.
//!
//! ```text
//! wheelflat [--preset table4.4-flat] [--speed KMH] [--flat SIDE:LEN_MM:DEPTH_MM:ANGLE_DEG[:chord]]...
//!           [--no-flats] [--contact adaptive|hertz] [--kw N/m/rad] [--ch N/m^1.5]
//!           [--n NODES_PER_SPAN] [--between-nodes beam|linear] [--dt-us US] [--spans N]
//!           [--window AHEAD[:BEHIND]] [--start M] [--site M]... [--duration S]
//!           [--every K] [--output FILE.csv]
//! ```
//!
//! The presets are the thesis' fixed tracks; `--window 10` runs the FMUs' default, the
//! endless track with 10 m kept ahead and behind (`--window 20`: the converged window).
//!
//! `wheelflat receptance ...` and `wheelflat receptance-fit MEASURED.csv ...`: the
//! track's receptance and a fit to a measured one (issue 44; `wheelflat/receptance.rs`).
//! `wheelflat spectra` and `wheelflat profile --spectrum NAME ...`: the standard track
//! spectra's RMS over a band and a drawn rail profile (issue 44; `wheelflat/profile.rs`).

use std::io::{BufWriter, Write};
use std::process::ExitCode;
use std::time::Instant;
use wheelflat::contact::ContactModel;
use wheelflat::sim::{Scenario, Simulation, TrackWindow, kmh};
use wheelflat::track::RailBetweenNodes;
use wheelflat::wheel::{FlatShape, FlatSpec};

#[path = "wheelflat/profile.rs"]
mod profile;
#[path = "wheelflat/receptance.rs"]
mod receptance;

const USAGE: &str = "usage: wheelflat [--preset NAME] [--speed KMH] \
[--flat SIDE:LEN_MM:DEPTH_MM:ANGLE_DEG[:haversine|chord]]... [--no-flats] \
[--contact adaptive|hertz] [--kw N/m/rad] [--ch N/m^1.5] [--n NODES_PER_SPAN] \
[--between-nodes beam|linear] [--dt-us US] \
[--spans N] [--window AHEAD[:BEHIND]] [--start M] [--site M]... [--duration S] [--every K] \
[--output FILE.csv]
presets (the thesis' fixed tracks): table4.4 table4.4-flat (default) table4.1 table5.1 \
table5.2 chapter2; --window 10: the FMUs' default endless track
subcommands: wheelflat receptance ..., wheelflat receptance-fit MEASURED.csv ... \
(wheelflat receptance --help); wheelflat spectra ..., wheelflat profile ... \
(wheelflat profile --help)";

fn num(flag: &str, v: Option<String>) -> Result<f64, String> {
    let v = v.ok_or_else(|| format!("{flag} needs a value"))?;
    v.parse::<f64>()
        .map_err(|_| format!("{flag}: `{v}` is not a number"))
}

fn parse_flat(v: &str) -> Result<(usize, FlatSpec), String> {
    let parts: Vec<&str> = v.split(':').collect();
    if parts.len() < 4 || parts.len() > 5 {
        return Err(format!(
            "--flat `{v}`: expected SIDE:LEN_MM:DEPTH_MM:ANGLE_DEG[:haversine|chord]"
        ));
    }
    let side = match parts[0] {
        "left" | "l" | "0" => 0,
        "right" | "r" | "1" => 1,
        s => return Err(format!("--flat side `{s}`: expected left or right")),
    };
    let f = |s: &str, what: &str| {
        s.parse::<f64>()
            .map_err(|_| format!("--flat {what} `{s}` is not a number"))
    };
    let length = f(parts[1], "length")? * 1e-3;
    let depth_mm = f(parts[2], "depth")?;
    let angle = f(parts[3], "angle")?.to_radians();
    let shape = match parts.get(4).copied().unwrap_or("haversine") {
        "haversine" => FlatShape::Haversine,
        "chord" => FlatShape::Chord,
        s => return Err(format!("--flat shape `{s}`: expected haversine or chord")),
    };
    let depth = if shape == FlatShape::Chord && depth_mm == 0.0 {
        None
    } else {
        Some(depth_mm * 1e-3)
    };
    Ok((
        side,
        FlatSpec {
            length,
            depth,
            angle,
            shape,
        },
    ))
}

fn run() -> Result<(), String> {
    let rest = || std::env::args().skip(2).collect();
    match std::env::args().nth(1).as_deref() {
        Some("spectra") => return profile::spectra(rest()),
        Some("profile") => return profile::profile(rest()),
        Some("receptance") => return receptance::receptance(rest()),
        Some("receptance-fit") => return receptance::receptance_fit(rest()),
        _ => {}
    }
    let mut args = std::env::args().skip(1);
    let mut scenario = Scenario::table_4_4_flat();
    let mut flats: Vec<(usize, FlatSpec)> = Vec::new();
    let mut clear_flats = false;
    let mut duration = 0.8;
    let mut every = 1u64;
    let mut output = String::from("wheelflat.csv");
    let mut pending: Vec<(String, Option<String>)> = Vec::new();
    while let Some(a) = args.next() {
        match a.as_str() {
            "-h" | "--help" => {
                println!("{USAGE}");
                return Ok(());
            }
            "--no-flats" => clear_flats = true,
            "--preset" => {
                let name = args.next().ok_or("--preset needs a value")?;
                scenario = Scenario::preset(&name).ok_or_else(|| {
                    format!("unknown preset `{name}`; one of {:?}", Scenario::PRESETS)
                })?;
            }
            _ if a.starts_with("--") => pending.push((a.clone(), args.next())),
            _ => return Err(format!("unexpected argument `{a}`\n{USAGE}")),
        }
    }
    for (flag, v) in pending {
        match flag.as_str() {
            "--speed" => scenario.speed = kmh(num(&flag, v)?),
            "--flat" => flats.push(parse_flat(&v.ok_or("--flat needs a value")?)?),
            "--contact" => {
                scenario.contact_model = match v.as_deref() {
                    Some("adaptive") => ContactModel::Adaptive,
                    Some("hertz") => ContactModel::Hertz,
                    o => return Err(format!("--contact {o:?}: expected adaptive or hertz")),
                }
            }
            "--between-nodes" => scenario.set_between_nodes(match v.as_deref() {
                Some("beam") => RailBetweenNodes::Beam,
                Some("linear") => RailBetweenNodes::Linear,
                o => {
                    return Err(format!(
                        "--between-nodes {o:?}: expected beam (the default) or linear (the \
                         thesis' (3.23))"
                    ));
                }
            }),
            "--kw" => scenario.kw = num(&flag, v)?,
            "--ch" => scenario.hertz_coefficient = num(&flag, v)?,
            "--n" => {
                let n = num(&flag, v)?;
                if !(n >= 1.0 && n.fract() == 0.0) {
                    return Err(format!("--n {n}: expected a whole number >= 1"));
                }
                scenario.set_nodes_per_span(n as usize)
            }
            "--spans" => {
                let n = num(&flag, v)?;
                if !(n >= 2.0 && n.fract() == 0.0) {
                    return Err(format!("--spans {n}: expected a whole number >= 2"));
                }
                scenario.set_spans(n as usize)
            }
            "--dt-us" => scenario.dt = num(&flag, v)? * 1e-6,
            "--window" => {
                let v = v.ok_or("--window needs a value (m): AHEAD[:BEHIND]")?;
                let (ahead, behind) = match v.split_once(':') {
                    Some((a, b)) => (a.to_string(), b.to_string()),
                    None => (v.clone(), v.clone()),
                };
                scenario.window = Some(TrackWindow {
                    ahead: num(&flag, Some(ahead))?,
                    behind: num(&flag, Some(behind))?,
                    ..TrackWindow::DEFAULT
                });
            }
            "--start" => scenario.start_position = num(&flag, v)?,
            "--site" => scenario.sites.push(num(&flag, v)?),
            "--duration" => duration = num(&flag, v)?,
            "--every" => {
                let k = num(&flag, v)?;
                if !(k >= 1.0 && k.fract() == 0.0) {
                    return Err(format!("--every {k}: expected a whole number >= 1"));
                }
                every = k as u64
            }
            "--output" => output = v.ok_or("--output needs a value")?,
            _ => return Err(format!("unknown option `{flag}`\n{USAGE}")),
        }
    }
    if clear_flats {
        scenario.flats = [Vec::new(), Vec::new()];
    }
    for (side, f) in flats {
        scenario.flats[side].push(f);
    }
    if !(duration.is_finite() && duration > 0.0) {
        return Err(format!("--duration {duration}: expected > 0 s"));
    }
    let mut sim = Simulation::new(&scenario).map_err(|e| e.to_string())?;
    eprintln!(
        "{}: V = {:.1} km/h, dt = {:.2} us, static wheel load {:.2} kN, K_w = {:.4e} N/m/rad",
        scenario.name,
        scenario.speed * 3.6,
        sim.dt() * 1e6,
        sim.static_load()[0] * 1e-3,
        sim.contact_law().kw
    );
    let file = std::fs::File::create(&output).map_err(|e| format!("{output}: {e}"))?;
    let mut w = BufWriter::new(file);
    writeln!(
        w,
        "time_s,position_m,rotation_rad,force_left_N,force_right_N,wheel_z_left_m,wheel_z_right_m,\
rail_z_left_m,rail_z_right_m,overlap_left_m,overlap_right_m,front_angle_left_rad,rear_angle_left_rad,\
front_angle_right_rad,rear_angle_right_rad,contact_length_left_m,contact_length_right_m"
    )
    .map_err(|e| e.to_string())?;
    let total = (duration / sim.dt()).round() as u64;
    let start = Instant::now();
    let mut last_report = Instant::now();
    let mut io_err = None;
    for i in 0..total {
        let s = sim.step().map_err(|e| e.to_string())?;
        if i % every == 0 {
            let c = &s.contact;
            if let Err(e) = writeln!(
                w,
                "{:.8},{:.6},{:.6},{:.3},{:.3},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e},{:.6e}",
                s.time,
                s.position,
                s.rotation,
                c[0].force,
                c[1].force,
                s.wheel_z[0],
                s.wheel_z[1],
                s.rail_z[0],
                s.rail_z[1],
                c[0].overlap,
                c[1].overlap,
                c[0].front_angle,
                c[0].rear_angle,
                c[1].front_angle,
                c[1].rear_angle,
                c[0].length,
                c[1].length
            ) {
                io_err = Some(e);
                break;
            }
        }
        if last_report.elapsed().as_secs_f64() > 2.0 {
            last_report = Instant::now();
            eprintln!(
                "progress: {:.0}% (t = {:.3} s of {duration} s)",
                100.0 * i as f64 / total as f64,
                s.time
            );
        }
    }
    if let Some(e) = io_err {
        return Err(format!("{output}: {e}"));
    }
    w.flush().map_err(|e| format!("{output}: {e}"))?;
    let mx = sim.max_force();
    let st = sim.static_load();
    println!(
        "peak impact force: left {:.1} kN ({:.2} x static), right {:.1} kN ({:.2} x static)",
        mx[0] * 1e-3,
        mx[0] / st[0],
        mx[1] * 1e-3,
        mx[1] / st[1]
    );
    for site in sim.sites() {
        let (mx, mn) = (site.max(), site.min());
        // Rail seat force, bending moment (largest sagging), shear force (largest
        // magnitude) and ballast force, per rail.
        let side = |r: usize| {
            format!(
                "seat {:.1} kN, moment {:.1} kN m, shear {:.1} kN, ballast {:.1} kN",
                mx[r][3] * 1e-3,
                mx[r][1] * 1e-3,
                mx[r][2].max(-mn[r][2]) * 1e-3,
                mx[r][5] * 1e-3
            )
        };
        println!(
            "site at {:.3} m, largest: left {}; right {}",
            site.position(),
            side(0),
            side(1)
        );
    }
    eprintln!("{total} steps; wrote {output}");
    eprintln!("wall time: {:.2} s", start.elapsed().as_secs_f64());
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
