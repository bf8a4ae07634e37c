//! The runner's subcommands `receptance` and `receptance-fit` (issue 44): the track's
//! receptance computed from the model, and its pads and ballast fitted to a measured
//! one. The work is the library's (`wheelflat::track::track_receptance`,
//! `wheelflat::track::fit_receptance`); this parses the options and writes the CSV.

use nalgebra::Complex;
use std::io::{BufWriter, Write};
use std::time::Instant;
use wheelflat::sim::{Scenario, TrackSpec};
use wheelflat::track::{
    FitOptions, FitParameter, LoadAt, LoadedRails, ReceptanceSetup, ResponseAt, TrackParams,
    fit_receptance, log_frequencies, track_receptance,
};

pub const USAGE: &str = "usage: wheelflat receptance [--at sleeper|midspan] [--rails one|both] \
[--response point|other-rail|DIST_M] [--from HZ] [--to HZ] [--points N] [TRACK] [--output FILE.csv]
       wheelflat receptance-fit MEASURED.csv [--band FROM:TO] [--fit kp,cp,kb,cb[,ms]] \
[--at ..] [--rails ..] [--response ..] [TRACK] [--output FITTED.csv]
TRACK (the FMUs' default track, table 4.4 at n = 8, unless given; the starting guess of a \
fit): --n NODES_PER_SPAN --kp N/m --cp N.s/m --kb N/m --cb N.s/m --ms KG --js KG.M2; \
numerics: --spans N (400) --duration S (0.25)
CSV columns: frequency_Hz,magnitude_m_per_N,phase_deg,real,imag (m/N, the rail's \
displacement in the direction of the force per force on each loaded rail; a measured \
file may give real,imag or magnitude_m_per_N,phase_deg)";

/// Prints the usage when asked for.
fn help(args: &[String]) -> bool {
    let asked = args.iter().any(|a| a == "-h" || a == "--help");
    if asked {
        println!("{USAGE}");
    }
    asked
}

/// The options both subcommands share.
struct Common {
    track: TrackParams,
    setup: ReceptanceSetup,
    output: Option<String>,
}

/// A number for `flag` in `lo..=hi` (`unit` for the message).
fn number(flag: &str, v: Option<String>, lo: f64, hi: f64, unit: &str) -> Result<f64, String> {
    let v = v.ok_or_else(|| format!("{flag} needs a value ({lo} to {hi} {unit})"))?;
    let x: f64 = v
        .parse()
        .map_err(|_| format!("{flag} `{v}`: not a number; expected {lo} to {hi} {unit}"))?;
    if !(x.is_finite() && x >= lo && x <= hi) {
        return Err(format!(
            "{flag} {v}: out of range; expected {lo} to {hi} {unit}"
        ));
    }
    Ok(x)
}

/// A whole number for `flag` in `lo..=hi`.
fn whole(flag: &str, v: Option<String>, lo: usize, hi: usize) -> Result<usize, String> {
    let x = number(flag, v, lo as f64, hi as f64, "")?;
    if x.fract() != 0.0 {
        return Err(format!(
            "{flag} {x}: expected a whole number from {lo} to {hi}"
        ));
    }
    Ok(x as usize)
}

/// The FMUs' default track: table 4.4 at the converged grid n = 8.
fn default_track() -> TrackParams {
    match Scenario::table_4_4().track {
        TrackSpec::Discrete(p) => p,
        _ => unreachable!("table 4.4 has the discrete track"),
    }
}

/// Parses the shared options; the others go to `other` (flag, value), which returns
/// whether it took the flag.
fn parse(
    args: Vec<String>,
    mut other: impl FnMut(&str, &mut dyn Iterator<Item = String>) -> Result<bool, String>,
) -> Result<Common, String> {
    let mut c = Common {
        track: default_track(),
        setup: ReceptanceSetup::default(),
        output: None,
    };
    let mut args = args.into_iter();
    while let Some(a) = args.next() {
        let p = &mut c.track;
        match a.as_str() {
            "--at" => {
                c.setup.at = match args.next().as_deref() {
                    Some("sleeper") => LoadAt::Sleeper,
                    Some("midspan") => LoadAt::MidSpan,
                    v => return Err(format!("--at `{}`: expected sleeper or midspan", v.unwrap_or_default())),
                }
            }
            "--rails" => {
                c.setup.rails = match args.next().as_deref() {
                    Some("one") => LoadedRails::One,
                    Some("both") => LoadedRails::Both,
                    v => return Err(format!("--rails `{}`: expected one or both", v.unwrap_or_default())),
                }
            }
            "--response" => {
                c.setup.response = match args.next().as_deref() {
                    Some("point") => ResponseAt::Point,
                    Some("other-rail") => ResponseAt::OtherRail,
                    Some(v) => ResponseAt::Along(v.parse().ok().filter(|d: &f64| d.is_finite()).ok_or_else(|| {
                        format!("--response `{v}`: expected point, other-rail or a distance along the rail (m)")
                    })?),
                    None => return Err("--response needs a value: point, other-rail or DIST_M".into()),
                }
            }
            "--n" => p.nodes_per_span = whole(&a, args.next(), 1, 64)?,
            "--kp" => p.pad_stiffness = number(&a, args.next(), 1e5, 1e11, "N/m")?,
            "--cp" => p.pad_damping = number(&a, args.next(), 0.0, 1e8, "N.s/m")?,
            "--kb" => p.ballast_stiffness = number(&a, args.next(), 1e5, 1e11, "N/m")?,
            "--cb" => p.ballast_damping = number(&a, args.next(), 0.0, 1e8, "N.s/m")?,
            "--ms" => p.sleeper_mass = number(&a, args.next(), 10.0, 1e4, "kg")?,
            "--js" => p.sleeper_inertia = number(&a, args.next(), 0.1, 1e4, "kg.m2")?,
            "--spans" => c.setup.spans = whole(&a, args.next(), 20, 20_000)?,
            "--duration" => c.setup.duration = number(&a, args.next(), 0.01, 10.0, "s")?,
            "--output" => c.output = Some(args.next().ok_or("--output needs a file name")?),
            _ => {
                if !other(&a, &mut args)? {
                    return Err(format!("unknown option `{a}`\n{USAGE}"));
                }
            }
        }
    }
    Ok(c)
}

/// What the receptance is, in words.
fn describe(s: &ReceptanceSetup) -> String {
    let at = match s.at {
        LoadAt::Sleeper => "at a sleeper",
        LoadAt::MidSpan => "at mid-span",
    };
    let rails = match s.rails {
        LoadedRails::One => "one rail",
        LoadedRails::Both => "both rails",
    };
    let response = match s.response {
        ResponseAt::Point => "point receptance".to_string(),
        ResponseAt::OtherRail => "transfer to the other rail".to_string(),
        ResponseAt::Along(d) => format!("transfer {d} m along the rail"),
    };
    format!("{response}, load {at} on {rails}")
}

fn write_csv(path: &str, f: &[f64], a: &[Complex<f64>]) -> Result<(), String> {
    let file = std::fs::File::create(path).map_err(|e| format!("--output {path}: {e}"))?;
    let mut w = BufWriter::new(file);
    let mut go = || -> std::io::Result<()> {
        writeln!(w, "frequency_Hz,magnitude_m_per_N,phase_deg,real,imag")?;
        for (f, a) in f.iter().zip(a) {
            writeln!(
                w,
                "{f:.6},{:.9e},{:.6},{:.9e},{:.9e}",
                a.norm(),
                a.arg().to_degrees(),
                a.re,
                a.im
            )?;
        }
        w.flush()
    };
    go().map_err(|e| format!("--output {path}: {e}"))
}

/// The local maxima of `|a|` (indices), the ends left out.
fn maxima(a: &[Complex<f64>]) -> Vec<usize> {
    (1..a.len().saturating_sub(1))
        .filter(|&i| a[i].norm() > a[i - 1].norm() && a[i].norm() >= a[i + 1].norm())
        .collect()
}

/// `wheelflat receptance ...`
pub fn receptance(args: Vec<String>) -> Result<(), String> {
    if help(&args) {
        return Ok(());
    }
    let (mut from, mut to, mut points) = (20.0, 3000.0, 200usize);
    let c = parse(args, |flag, args| {
        match flag {
            "--from" => from = number(flag, args.next(), 1.0, 20_000.0, "Hz")?,
            "--to" => to = number(flag, args.next(), 1.0, 20_000.0, "Hz")?,
            "--points" => points = whole(flag, args.next(), 2, 100_000)?,
            _ => return Ok(false),
        }
        Ok(true)
    })?;
    let f = log_frequencies(from, to, points).map_err(|e| e.to_string())?;
    let output = c.output.unwrap_or_else(|| "receptance.csv".into());
    let t0 = Instant::now();
    let a = track_receptance(&c.track, &c.setup, &f).map_err(|e| e.to_string())?;
    let wall = t0.elapsed().as_secs_f64();
    write_csv(&output, &f, &a)?;
    println!(
        "{}, {from} Hz to {to} Hz, {points} frequencies; track n = {}, {} spans, {} s",
        describe(&c.setup),
        c.track.nodes_per_span,
        c.setup.spans,
        c.setup.duration
    );
    for i in maxima(&a) {
        println!(
            "local maximum: {:.1} Hz, {:.3e} m/N, {:.1} deg",
            f[i],
            a[i].norm(),
            a[i].arg().to_degrees()
        );
    }
    println!("wrote {output}");
    eprintln!("wall time: {wall:.2} s");
    Ok(())
}

/// The measured receptance of a CSV file: (frequencies, values).
fn read_measured(path: &str) -> Result<(Vec<f64>, Vec<Complex<f64>>), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let (_, head) = lines
        .next()
        .ok_or_else(|| format!("{path}: empty; expected a header line and rows"))?;
    let cols: Vec<&str> = head.split(',').map(str::trim).collect();
    let col = |name: &str| cols.iter().position(|c| *c == name);
    let freq = col("frequency_Hz").ok_or_else(|| {
        format!("{path}: line 1: no column frequency_Hz (the header reads `{head}`)")
    })?;
    let pair = match (
        col("real"),
        col("imag"),
        col("magnitude_m_per_N"),
        col("phase_deg"),
    ) {
        (Some(r), Some(i), _, _) => (r, i, true),
        (_, _, Some(m), Some(p)) => (m, p, false),
        _ => {
            return Err(format!(
                "{path}: line 1: expected the columns real,imag or magnitude_m_per_N,phase_deg \
                 (the header reads `{head}`)"
            ));
        }
    };
    let (mut f, mut a) = (Vec::new(), Vec::new());
    for (n, line) in lines {
        let v: Vec<&str> = line.split(',').map(str::trim).collect();
        let get = |k: usize| -> Result<f64, String> {
            v.get(k)
                .and_then(|s| s.parse::<f64>().ok())
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    format!(
                        "{path}: line {}: `{line}`: column {} is not a number",
                        n + 1,
                        k + 1
                    )
                })
        };
        f.push(get(freq)?);
        let (x, y) = (get(pair.0)?, get(pair.1)?);
        a.push(if pair.2 {
            Complex::new(x, y)
        } else {
            Complex::from_polar(x, y.to_radians())
        });
    }
    if f.is_empty() {
        return Err(format!("{path}: no rows"));
    }
    Ok((f, a))
}

/// `wheelflat receptance-fit MEASURED.csv ...`
pub fn receptance_fit(args: Vec<String>) -> Result<(), String> {
    if help(&args) {
        return Ok(());
    }
    let mut options = FitOptions::default();
    let mut measured: Option<String> = None;
    let c = parse(args, |flag, args| {
        match flag {
            "--band" => {
                let v = args.next().ok_or("--band needs a value: FROM:TO (Hz)")?;
                let (a, b) = v
                    .split_once(':')
                    .ok_or_else(|| format!("--band `{v}`: expected FROM:TO (Hz), e.g. 20:3000"))?;
                options.band = (
                    number("--band FROM", Some(a.into()), 1.0, 20_000.0, "Hz")?,
                    number("--band TO", Some(b.into()), 1.0, 20_000.0, "Hz")?,
                );
            }
            "--fit" => {
                let v = args.next().ok_or("--fit needs a value: e.g. kp,cp,kb,cb")?;
                options.parameters = v
                    .split(',')
                    .map(|s| {
                        FitParameter::from_short(s.trim()).ok_or_else(|| {
                            format!("--fit `{v}`: `{s}` is none of kp, cp, kb, cb, ms")
                        })
                    })
                    .collect::<Result<_, _>>()?;
            }
            f if !f.starts_with("--") && measured.is_none() => measured = Some(f.to_string()),
            _ => return Ok(false),
        }
        Ok(true)
    })?;
    let measured = measured.ok_or_else(|| format!("no measured receptance given\n{USAGE}"))?;
    let (f, m) = read_measured(&measured)?;
    options.setup = c.setup;
    let output = c.output.unwrap_or_else(|| "receptance_fit.csv".into());
    let t0 = Instant::now();
    let fit = fit_receptance(&c.track, &f, &m, &options).map_err(|e| e.to_string())?;
    let wall = t0.elapsed().as_secs_f64();
    write_csv(&output, &fit.frequencies, &fit.fitted)?;
    println!(
        "fitted {} to {} frequencies from {} Hz to {} Hz ({}): {} iterations, {}",
        options
            .parameters
            .iter()
            .map(|p| p.short())
            .collect::<Vec<_>>()
            .join(", "),
        fit.frequencies.len(),
        options.band.0,
        options.band.1,
        describe(&options.setup),
        fit.iterations,
        if fit.converged {
            "converged"
        } else {
            "NOT converged (--band, --fit or the starting track may help)"
        }
    );
    for v in &fit.values {
        println!(
            "{} {}: {:.4e} +- {:.2e} ({:.2} %; start {:.4e})",
            v.parameter.short(),
            v.parameter.name(),
            v.value,
            v.standard_error,
            100.0 * v.standard_error / v.value,
            v.start
        );
    }
    println!(
        "residual: {:.3} dB RMS in magnitude, {:.3} deg RMS in phase",
        fit.rms_db, fit.rms_deg
    );
    println!("wrote {output}");
    eprintln!("wall time: {wall:.2} s ({} receptances)", fit.evaluations);
    Ok(())
}
