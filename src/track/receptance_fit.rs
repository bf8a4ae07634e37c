//! The track's pads and ballast (and optionally its sleeper mass) fitted to a measured
//! receptance (issue 44).
//!
//! Levenberg-Marquardt least squares on the complex logarithm of the ratio of the
//! model's receptance ([`super::track_receptance`]) to the measured one at each
//! measured frequency in the band: the residuals are `ln |alpha_model / alpha_measured|`
//! (log magnitude, nepers) and `arg(alpha_model / alpha_measured)` (phase, rad), equal
//! weights (one neper, 8.69 dB, weighs as one radian, 57.3 degrees), so a frequency
//! counts alike wherever the receptance's magnitude is. The parameters are fitted as
//! their logarithms, so they stay positive, and a step changes none by more than a
//! factor `e`. The Jacobian is a forward difference in the logarithm (step 1e-4, one
//! receptance per parameter); the damping is Marquardt's (`J^T J + mu diag(J^T J)`).
//!
//! The spread of each fitted value is its standard error from the Jacobian at the
//! solution: `sigma^2 (J^T J)^-1` in the logarithms, `sigma^2` the residuals' sum of
//! squares over their count less the parameters', times the value (the delta method).
//! It is the spread the measurement's scatter leaves, not a bound on the model's error.

use super::receptance::receptance_with_dt;
use super::*;
use nalgebra::Complex;

/// One receptance of the fit: the residuals (log magnitude and phase at each
/// frequency in turn) and the receptance (m/N).
type Evaluation = (Vec<f64>, Vec<Complex<f64>>);

/// A track parameter the fit can adjust.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FitParameter {
    /// Pad stiffness `K_p` (N/m).
    PadStiffness,
    /// Pad damping `C_p` (N s/m).
    PadDamping,
    /// Ballast stiffness `K_b` at each rail seat (N/m).
    BallastStiffness,
    /// Ballast damping `C_b` at each rail seat (N s/m).
    BallastDamping,
    /// Sleeper mass `m_s` (kg); the roll inertia `J_s` is scaled with it (the same
    /// sleeper's shape).
    SleeperMass,
}

impl FitParameter {
    /// Every fit parameter, in the order of their short names `kp, cp, kb, cb, ms`.
    pub const ALL: [FitParameter; 5] = [
        FitParameter::PadStiffness,
        FitParameter::PadDamping,
        FitParameter::BallastStiffness,
        FitParameter::BallastDamping,
        FitParameter::SleeperMass,
    ];

    /// The short name (`kp`, `cp`, `kb`, `cb`, `ms`).
    pub fn short(self) -> &'static str {
        match self {
            FitParameter::PadStiffness => "kp",
            FitParameter::PadDamping => "cp",
            FitParameter::BallastStiffness => "kb",
            FitParameter::BallastDamping => "cb",
            FitParameter::SleeperMass => "ms",
        }
    }

    /// The parameter's name and unit, as the FMUs name it.
    pub fn name(self) -> &'static str {
        match self {
            FitParameter::PadStiffness => "track.pad.stiffness (N/m)",
            FitParameter::PadDamping => "track.pad.damping (N s/m)",
            FitParameter::BallastStiffness => "track.ballast.stiffness (N/m)",
            FitParameter::BallastDamping => "track.ballast.damping (N s/m)",
            FitParameter::SleeperMass => "track.sleeper.mass (kg)",
        }
    }

    /// The parameter of a short name; `None` for any other text.
    pub fn from_short(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.short() == s)
    }

    /// Its value in `p`.
    pub fn get(self, p: &TrackParams) -> f64 {
        match self {
            FitParameter::PadStiffness => p.pad_stiffness,
            FitParameter::PadDamping => p.pad_damping,
            FitParameter::BallastStiffness => p.ballast_stiffness,
            FitParameter::BallastDamping => p.ballast_damping,
            FitParameter::SleeperMass => p.sleeper_mass,
        }
    }

    /// Sets it in `p` (the sleeper's roll inertia scaled with its mass).
    pub fn set(self, p: &mut TrackParams, v: f64) {
        match self {
            FitParameter::PadStiffness => p.pad_stiffness = v,
            FitParameter::PadDamping => p.pad_damping = v,
            FitParameter::BallastStiffness => p.ballast_stiffness = v,
            FitParameter::BallastDamping => p.ballast_damping = v,
            FitParameter::SleeperMass => {
                p.sleeper_inertia *= v / p.sleeper_mass;
                p.sleeper_mass = v;
            }
        }
    }
}

/// What to fit, and how.
#[derive(Debug, Clone, PartialEq)]
pub struct FitOptions {
    /// The parameters to adjust (at least one, none twice); the others keep the
    /// starting track's values.
    pub parameters: Vec<FitParameter>,
    /// The band (Hz): the measured frequencies from `band.0` to `band.1` are fitted.
    pub band: (f64, f64),
    /// The receptance computed: load, response and numerics (as the measurement).
    pub setup: ReceptanceSetup,
    /// The most Levenberg-Marquardt iterations.
    pub max_iterations: usize,
}

impl Default for FitOptions {
    /// `kp, cp, kb, cb` over 20 Hz to 3 kHz, the default receptance, 40 iterations.
    fn default() -> Self {
        FitOptions {
            parameters: FitParameter::ALL[..4].to_vec(),
            band: (20.0, 3000.0),
            setup: ReceptanceSetup::default(),
            max_iterations: 40,
        }
    }
}

/// One fitted parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FittedValue {
    /// Which.
    pub parameter: FitParameter,
    /// Its starting value.
    pub start: f64,
    /// Its fitted value.
    pub value: f64,
    /// Its standard error (same unit): `value sqrt(cov_ii)`, `cov = sigma^2 (J^T
    /// J)^-1` in the logarithms.
    pub standard_error: f64,
}

/// The result of [`fit_receptance`].
#[derive(Debug, Clone, PartialEq)]
pub struct ReceptanceFit {
    /// The fitted track (the starting track with the fitted values).
    pub params: TrackParams,
    /// The fitted values with their spread, in the order asked for.
    pub values: Vec<FittedValue>,
    /// The measured frequencies in the band (Hz).
    pub frequencies: Vec<f64>,
    /// The fitted track's receptance there (m/N).
    pub fitted: Vec<Complex<f64>>,
    /// RMS of the magnitude's residual, `20 log10 |alpha_model / alpha_measured|` (dB).
    pub rms_db: f64,
    /// RMS of the phase's residual (degrees).
    pub rms_deg: f64,
    /// Iterations taken.
    pub iterations: usize,
    /// Receptances computed.
    pub evaluations: usize,
    /// Whether the last step changed the cost by less than 1e-9 of it and no
    /// parameter by more than 1e-6 of itself.
    pub converged: bool,
}

/// Fits `options.parameters` of the track `start` (also the starting guess) so that
/// its receptance matches `measured` (m/N, complex, displacement in the force's
/// direction) at `frequencies` (Hz; those in `options.band` are used).
///
/// Errors: a band outside [`RECEPTANCE_FREQUENCY_RANGE`] or empty; no more measured
/// frequencies in it than parameters; lengths that differ; a measured value that is zero or not finite; no parameter or one twice; a
/// starting value that is not positive; the receptance's own errors
/// ([`super::track_receptance`]).
pub fn fit_receptance(
    start: &TrackParams,
    frequencies: &[f64],
    measured: &[Complex<f64>],
    options: &FitOptions,
) -> Result<ReceptanceFit> {
    let (lo, hi) = RECEPTANCE_FREQUENCY_RANGE;
    let (b0, b1) = options.band;
    if !(b0.is_finite() && b1.is_finite() && lo <= b0 && b0 < b1 && b1 <= hi) {
        return Err(out_of_range(
            "--band",
            if b0.is_finite() && b0 >= lo { b1 } else { b0 },
            format!("FROM:TO with {lo} Hz <= FROM < TO <= {hi} Hz (here {b0}:{b1})"),
        ));
    }
    if frequencies.len() != measured.len() {
        return Err(out_of_range(
            "measured receptance",
            measured.len() as f64,
            format!("one value per frequency ({})", frequencies.len()),
        ));
    }
    let pars = &options.parameters;
    if pars.is_empty() {
        return Err(out_of_range(
            "--fit",
            0.0,
            "at least one of kp, cp, kb, cb, ms",
        ));
    }
    for (i, q) in pars.iter().enumerate() {
        if pars[..i].contains(q) {
            return Err(Error::Unsupported(format!(
                "--fit names {} twice",
                q.short()
            )));
        }
        positive(q.name(), q.get(start), "(starting value)")?;
    }
    let used: Vec<usize> = (0..frequencies.len())
        .filter(|&i| (b0..=b1).contains(&frequencies[i]))
        .collect();
    if used.len() <= pars.len() {
        return Err(out_of_range(
            "--band",
            b0,
            format!(
                "a band that holds more measured frequencies than the {} fitted \
                 parameters: {b0}:{b1} Hz holds {}",
                pars.len(),
                used.len()
            ),
        ));
    }
    let freqs: Vec<f64> = used.iter().map(|&i| frequencies[i]).collect();
    let meas: Vec<Complex<f64>> = used.iter().map(|&i| measured[i]).collect();
    if let Some((f, a)) = freqs
        .iter()
        .zip(&meas)
        .find(|(_, a)| !(a.re.is_finite() && a.im.is_finite() && a.norm() > 0.0))
    {
        return Err(out_of_range(
            "measured receptance",
            a.norm(),
            format!("finite and not zero (at {f} Hz)"),
        ));
    }
    let setup = options.setup;
    let mut base = *start;
    base.spans = setup.spans;
    base.validate()?;
    let dt0 = setup.dt_fraction * base.critical_time_step().0;
    let mut evaluations = 0;
    // The receptance of the track with log-parameters `th`, and its residuals.
    let mut model = |th: &[f64]| -> Result<Evaluation> {
        let mut p = base;
        for (q, t) in pars.iter().zip(th) {
            q.set(&mut p, t.exp());
        }
        p.validate()?;
        let dtc = p.critical_time_step().0;
        let dt = if dt0 <= dtc {
            dt0
        } else {
            setup.dt_fraction * dtc
        };
        evaluations += 1;
        let a = receptance_with_dt(&p, &setup, &freqs, dt)?;
        let mut r = Vec::with_capacity(2 * a.len());
        for (m, d) in a.iter().zip(&meas) {
            let l = (m / d).ln();
            r.push(l.re);
            r.push(l.im);
        }
        Ok((r, a))
    };
    let cost = |r: &[f64]| 0.5 * r.iter().map(|x| x * x).sum::<f64>();
    let np = pars.len();
    let mut th: Vec<f64> = pars.iter().map(|q| q.get(start).ln()).collect();
    let (mut r, mut a) = model(&th)?;
    let mut c = cost(&r);
    let mut mu = 1e-3;
    let mut converged = false;
    let mut iterations = 0;
    const H: f64 = 1e-4;
    let jacobian = |th: &[f64],
                    r: &[f64],
                    model: &mut dyn FnMut(&[f64]) -> Result<Evaluation>|
     -> Result<DMatrix<f64>> {
        let mut j = DMatrix::<f64>::zeros(r.len(), th.len());
        for k in 0..th.len() {
            let mut t = th.to_vec();
            t[k] += H;
            let (rk, _) = model(&t)?;
            for i in 0..r.len() {
                j[(i, k)] = (rk[i] - r[i]) / H;
            }
        }
        Ok(j)
    };
    while iterations < options.max_iterations && !converged {
        iterations += 1;
        let j = jacobian(&th, &r, &mut model)?;
        let jtj = j.transpose() * &j;
        let g = j.transpose() * DVector::from_column_slice(&r);
        loop {
            let mut lhs = jtj.clone();
            for k in 0..np {
                lhs[(k, k)] += mu * jtj[(k, k)].max(1e-12);
            }
            let Some(step) = lhs.cholesky().map(|ch| ch.solve(&(-&g))) else {
                mu *= 4.0;
                continue;
            };
            let step: Vec<f64> = step.iter().map(|s| s.clamp(-1.0, 1.0)).collect();
            let trial: Vec<f64> = th.iter().zip(&step).map(|(t, s)| t + s).collect();
            let (rt, at) = model(&trial)?;
            let ct = cost(&rt);
            if ct <= c {
                let small_step = step.iter().all(|s| s.abs() < 1e-6);
                converged = (c - ct) <= 1e-9 * c && small_step;
                (th, r, a, c) = (trial, rt, at, ct);
                mu = (mu / 3.0).max(1e-9);
                break;
            }
            mu *= 4.0;
            if mu > 1e12 {
                // No step lowers the cost: the minimum, to the model's resolution.
                converged = true;
                break;
            }
        }
    }
    // The spread, from the Jacobian at the solution.
    let j = jacobian(&th, &r, &mut model)?;
    let m = r.len();
    let sigma2 = 2.0 * c / (m - np).max(1) as f64;
    let cov = (j.transpose() * &j)
        .try_inverse()
        .unwrap_or_else(|| DMatrix::from_element(np, np, f64::NAN))
        * sigma2;
    let mut params = base;
    params.spans = start.spans;
    let values = pars
        .iter()
        .enumerate()
        .map(|(k, &q)| {
            let value = th[k].exp();
            q.set(&mut params, value);
            FittedValue {
                parameter: q,
                start: q.get(start),
                value,
                standard_error: value * cov[(k, k)].max(0.0).sqrt(),
            }
        })
        .collect();
    let n = (m / 2) as f64;
    let rms_db = (r.iter().step_by(2).map(|x| x * x).sum::<f64>() / n).sqrt() * 20.0
        / std::f64::consts::LN_10;
    let rms_deg = (r.iter().skip(1).step_by(2).map(|x| x * x).sum::<f64>() / n)
        .sqrt()
        .to_degrees();
    Ok(ReceptanceFit {
        params,
        values,
        frequencies: freqs,
        fitted: a,
        rms_db,
        rms_deg,
        iterations,
        evaluations,
        converged,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{Scenario, TrackSpec};

    /// Fits `parameters` of table 4.4's track to the model's own receptance (point,
    /// one rail, at a sleeper, the default numerics: 400 spans, 0.25 s) of a track
    /// whose values differ from it by 30 to 50 %, with 1 % multiplicative complex
    /// noise (seeded), 40 frequencies from 20 Hz to 3 kHz; each fitted value within
    /// 2 % of the truth.
    fn recovers(parameters: &[FitParameter]) {
        let TrackSpec::Discrete(start) = Scenario::table_4_4().track else {
            unreachable!("table 4.4 has the discrete track")
        };
        let mut truth = start;
        truth.pad_stiffness *= 1.4;
        truth.pad_damping *= 0.65;
        truth.ballast_stiffness *= 0.7;
        truth.ballast_damping *= 1.5;
        if parameters.contains(&FitParameter::SleeperMass) {
            FitParameter::SleeperMass.set(&mut truth, 1.3 * start.sleeper_mass);
        }
        let options = FitOptions {
            parameters: parameters.to_vec(),
            ..Default::default()
        };
        let f = log_frequencies(20.0, 3000.0, 40).unwrap();
        let clean = track_receptance(&truth, &options.setup, &f).unwrap();
        // Zero mean, unit variance: uniform in [-sqrt 3, sqrt 3], from the project's
        // seeded streams.
        let mut stream = crate::numerics::Stream::new(44, 0);
        let noise: Vec<f64> = (0..2 * f.len())
            .map(|_| (2.0 * stream.uniform() - 1.0) * 3f64.sqrt())
            .collect();
        let measured: Vec<Complex<f64>> = clean
            .iter()
            .enumerate()
            .map(|(i, a)| a * Complex::new(1.0 + 0.01 * noise[2 * i], 0.01 * noise[2 * i + 1]))
            .collect();
        let t0 = std::time::Instant::now();
        let fit = fit_receptance(&start, &f, &measured, &options).unwrap();
        let wall = t0.elapsed().as_secs_f64();
        assert!(fit.converged, "{fit:?}");
        for v in &fit.values {
            let truth = v.parameter.get(&truth);
            let err = v.value / truth - 1.0;
            eprintln!(
                "{}: start {:.4e}, fitted {:.4e} +- {:.2e}, truth {truth:.4e}: {:+.3} %",
                v.parameter.short(),
                v.start,
                v.value,
                v.standard_error,
                100.0 * err
            );
            assert!(err.abs() < 0.02, "{}: {err}", v.parameter.short());
            // The spread is of the error's size (1 % noise).
            assert!(v.standard_error > 0.0 && v.standard_error < 0.02 * truth);
        }
        eprintln!(
            "rms {:.3} dB, {:.3} deg; {} iterations, {} receptances, {wall:.1} s",
            fit.rms_db, fit.rms_deg, fit.iterations, fit.evaluations
        );
        // 1 % noise: 0.087 dB and 0.57 degrees RMS.
        assert!(fit.rms_db < 0.15 && fit.rms_deg < 1.0, "{fit:?}");
    }

    #[test]
    fn a_noisy_receptance_of_known_pads_and_ballast_is_fitted_within_two_percent() {
        recovers(&FitParameter::ALL[..4]);
    }

    #[test]
    fn a_noisy_receptance_of_known_pads_ballast_and_sleeper_is_fitted_within_two_percent() {
        recovers(&FitParameter::ALL);
    }

    #[test]
    fn refused_fits_name_what_is_wrong() {
        let TrackSpec::Discrete(start) = Scenario::table_4_4().track else {
            unreachable!()
        };
        let f = [100.0, 200.0];
        let m = [Complex::new(1e-9, 0.0); 2];
        let e = fit_receptance(&start, &f, &m, &FitOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains("--band"), "{e}");
        let options = FitOptions {
            band: (500.0, 100.0),
            ..Default::default()
        };
        let e = fit_receptance(&start, &f, &m, &options)
            .unwrap_err()
            .to_string();
        assert!(e.contains("--band") && e.contains("500"), "{e}");
        assert_eq!(
            FitParameter::from_short("kb"),
            Some(FitParameter::BallastStiffness)
        );
        assert_eq!(FitParameter::from_short("k"), None);
    }
}
