//! The runner's subcommands `spectra` and `profile` (issue 44): the standard track
//! spectra's RMS over a band, their target variance in each third of an octave, and a
//! drawn rail profile sampled along the line. The work is the library's
//! (`wheelflat::track::{TrackSpectrum, ProfileSpec}`,
//! `wheelflat::contact::RoughnessSpectrum`); this parses the options and writes.

use std::io::{BufWriter, Write};
use wheelflat::contact::{RoughnessSpectrum, hertz_half_length};
use wheelflat::sim::Scenario;
use wheelflat::track::{ProfileSpec, TrackSpectrum};

pub const USAGE: &str = "usage: wheelflat spectra [--band SHORTEST:LONGEST]
       wheelflat profile --spectrum NAME [--seed N] [--band SHORTEST:LONGEST] \
[--rails independent|cross_level] [--length M] [--dx M] [--output FILE.csv] [--target FILE.csv]
spectra: each spectrum's RMS height (mm) and slope over the band (m, default 1.5:30, \
the FMUs' default), the ISO 3095 roughness limit's RMS and the Hertz patch of table 4.4's \
wheel and load; profile: the rails drawn from spectrum NAME (fra_class_1 .. \
fra_class_6, ore_low, ore_high) with seed N (1), sampled every --dx (0.05 m) over \
--length (2000 m) from 0, without the ramp: columns x_m,left_m,right_m; --target writes \
the vertical spectrum's variance (each rail's with independent rails, their mean's \
with cross_level) in each third of an octave of the band: columns wavenumber_low_rad_per_m,wavenumber_high_rad_per_m,variance_m2";

fn value<'a>(args: &'a [String], flag: &str) -> Option<&'a str> {
    args.iter()
        .position(|a| a == flag)
        .and_then(|i| args.get(i + 1))
        .map(String::as_str)
}

fn number(args: &[String], flag: &str, default: f64) -> Result<f64, String> {
    match value(args, flag) {
        None => Ok(default),
        Some(v) => v
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{flag} `{v}` is not a finite number")),
    }
}

fn band(args: &[String]) -> Result<(f64, f64), String> {
    match value(args, "--band") {
        None => Ok((1.5, 30.0)),
        Some(v) => {
            let p: Vec<f64> = v.split(':').filter_map(|x| x.parse().ok()).collect();
            match p[..] {
                [a, b] if a >= b => Err(format!(
                    "--band `{v}`: SHORTEST:LONGEST, the shortest wavelength first (here {b}:{a}?)"
                )),
                [a, b] => Ok((a, b)),
                _ => Err(format!(
                    "--band `{v}`: expected SHORTEST:LONGEST in metres (1.5:30)"
                )),
            }
        }
    }
}

fn spectrum(name: &str) -> Result<TrackSpectrum, String> {
    TrackSpectrum::all()
        .into_iter()
        .find(|s| s.name() == name)
        .ok_or_else(|| {
            format!(
                "--spectrum `{name}`: expected one of {}",
                TrackSpectrum::all().map(|s| s.name()).join(", ")
            )
        })
}

/// Every argument a known flag followed by its value, each flag at most once.
fn check_flags(args: &[String], allowed: &[&str]) -> Result<(), String> {
    let mut i = 0;
    let mut seen = Vec::new();
    while i < args.len() {
        let flag = args[i].as_str();
        if !allowed.contains(&flag) {
            return Err(format!("unknown argument `{flag}`\n{USAGE}"));
        }
        if seen.contains(&flag) {
            return Err(format!("{flag} is given twice"));
        }
        seen.push(flag);
        match args.get(i + 1) {
            Some(v) if !v.starts_with("--") => {}
            _ => return Err(format!("{flag} needs a value")),
        }
        i += 2;
    }
    Ok(())
}

fn help(args: &[String]) -> bool {
    let asked = args.iter().any(|a| a == "-h" || a == "--help");
    if asked {
        println!("{USAGE}");
    }
    asked
}

/// `wheelflat spectra`: the table `docs/MODEL.md` quotes.
pub fn spectra(args: Vec<String>) -> Result<(), String> {
    if help(&args) {
        return Ok(());
    }
    check_flags(&args, &["--band"])?;
    let band = band(&args)?;
    let mut rows = Vec::new();
    for sp in TrackSpectrum::all() {
        let spec = ProfileSpec {
            spectrum: sp,
            seed: 0,
            band,
            cross_level: false,
            ramp: 1.0,
        };
        spec.validate().map_err(|e| e.to_string())?;
        let (lo, hi) = spec.wavenumbers();
        // The slope's variance: the integral of W^2 S, by the midpoint rule on a log grid.
        let n = 20_000;
        let r = (hi / lo).ln();
        let slope: f64 = (0..n)
            .map(|i| {
                let w = lo * (r * (i as f64 + 0.5) / n as f64).exp();
                w * w * sp.vertical(w) * w * r / n as f64
            })
            .sum();
        rows.push(format!(
            "{},{:.2},{:.3}",
            sp.name(),
            1e3 * spec.variance().sqrt(),
            1e3 * slope.sqrt()
        ));
    }
    println!(
        "spectrum,rms_height_mm,rms_slope_mrad (band {} m to {} m)",
        band.0, band.1
    );
    for r in rows {
        println!("{r}");
    }
    let iso = RoughnessSpectrum::iso3095();
    println!("iso3095 roughness limit RMS (um): {:.2}", 1e6 * iso.rms());
    let s = Scenario::table_4_4();
    let load = wheelflat::sim::Simulation::new(&s)
        .map_err(|e| e.to_string())?
        .static_load()[0];
    println!(
        "Hertz patch half-length at table 4.4's wheel and load (mm): {:.2} (R_w {} m, P {:.0} N, C_H {:e} N/m^1.5)",
        1e3 * hertz_half_length(s.wheel_radius, load, s.hertz_coefficient),
        s.wheel_radius,
        load,
        s.hertz_coefficient
    );
    Ok(())
}

/// `wheelflat profile`: a drawn profile sampled, and the target's band variances.
pub fn profile(args: Vec<String>) -> Result<(), String> {
    if help(&args) {
        return Ok(());
    }
    check_flags(
        &args,
        &[
            "--spectrum",
            "--seed",
            "--band",
            "--rails",
            "--length",
            "--dx",
            "--output",
            "--target",
        ],
    )?;
    let sp = spectrum(value(&args, "--spectrum").ok_or("--spectrum NAME is needed")?)?;
    let seed = match value(&args, "--seed") {
        None => 1,
        Some(v) => v
            .parse::<u32>()
            .ok()
            .filter(|&s| s <= i32::MAX as u32)
            .ok_or_else(|| {
                format!(
                    "--seed `{v}`: a whole number from 0 to {} (rail.spectrum.seed's range)",
                    i32::MAX
                )
            })?,
    };
    let cross_level = match value(&args, "--rails").unwrap_or("independent") {
        "independent" => false,
        "cross_level" => true,
        v => {
            return Err(format!(
                "--rails `{v}`: expected independent or cross_level"
            ));
        }
    };
    let spec = ProfileSpec {
        spectrum: sp,
        seed: u64::from(seed),
        band: band(&args)?,
        cross_level,
        ramp: 1.0,
    };
    spec.validate().map_err(|e| e.to_string())?;
    let (length, dx) = (
        number(&args, "--length", 2000.0)?,
        number(&args, "--dx", 0.05)?,
    );
    if !(dx > 0.0 && dx <= spec.band.0 / 4.0) {
        return Err(format!(
            "--dx {dx}: 0 < dx <= {} m (a quarter of the shortest wavelength)",
            spec.band.0 / 4.0
        ));
    }
    let n = (length / dx).round();
    if !(16.0..=1e8).contains(&n) {
        return Err(format!(
            "--length {length} and --dx {dx}: 16 to 1e8 samples (length / dx), here {n}"
        ));
    }
    let [l, r] = spec.series();
    let mut out: Box<dyn Write> = match value(&args, "--output") {
        Some(p) => Box::new(BufWriter::new(
            std::fs::File::create(p).map_err(|e| format!("--output {p}: {e}"))?,
        )),
        None => Box::new(BufWriter::new(std::io::stdout())),
    };
    let io = |e: std::io::Error| e.to_string();
    writeln!(out, "x_m,left_m,right_m").map_err(io)?;
    for i in 0..n as usize {
        let x = i as f64 * dx;
        writeln!(out, "{x},{:e},{:e}", l.at(x).0, r.at(x).0).map_err(io)?;
    }
    out.flush().map_err(io)?;
    if let Some(p) = value(&args, "--output") {
        eprintln!("wrote {p} ({n} samples every {dx} m, both rails, without the ramp)");
    }
    if let Some(p) = value(&args, "--target") {
        let mut t =
            BufWriter::new(std::fs::File::create(p).map_err(|e| format!("--target {p}: {e}"))?);
        writeln!(
            t,
            "wavenumber_low_rad_per_m,wavenumber_high_rad_per_m,variance_m2"
        )
        .map_err(io)?;
        let (lo, hi) = spec.wavenumbers();
        let bands = (3.0 * (hi / lo).log2()).ceil() as usize;
        let ratio = (hi / lo).powf(1.0 / bands as f64);
        for b in 0..bands {
            let (k0, k1) = (lo * ratio.powi(b as i32), lo * ratio.powi(b as i32 + 1));
            writeln!(t, "{k0},{k1},{:e}", sp.vertical_variance(k0, k1)).map_err(io)?;
        }
        t.flush().map_err(io)?;
        eprintln!("wrote {p} ({bands} thirds of an octave)");
    }
    Ok(())
}
