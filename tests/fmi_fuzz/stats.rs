//! What a run did: calls, fmi2OK and refusals per function, the slowest call.

use std::ffi::c_int;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;
use wheelflat::fmu::Call;

/// Statistics of a run.
pub struct Stats {
    pub calls: AtomicUsize,
    pub ok: AtomicUsize,
    pub refused: AtomicUsize,
    pub slowest_us: AtomicUsize,
    /// Per function (index of [`Call`]): calls, fmi2OK.
    pub per_call: [[AtomicUsize; 2]; 34],
}

impl Stats {
    pub fn count(&self, call: Call, status: c_int) {
        self.calls.fetch_add(1, Ordering::Relaxed);
        self.per_call[call as usize][0].fetch_add(1, Ordering::Relaxed);
        if status == 0 {
            self.per_call[call as usize][1].fetch_add(1, Ordering::Relaxed);
            self.ok.fetch_add(1, Ordering::Relaxed);
        } else {
            self.refused.fetch_add(1, Ordering::Relaxed);
        }
    }
}

impl Default for Stats {
    fn default() -> Stats {
        Stats {
            calls: AtomicUsize::new(0),
            ok: AtomicUsize::new(0),
            refused: AtomicUsize::new(0),
            slowest_us: AtomicUsize::new(0),
            per_call: std::array::from_fn(|_| [AtomicUsize::new(0), AtomicUsize::new(0)]),
        }
    }
}

impl Stats {
    /// Prints the counts of the run that started at `t0`.
    pub fn report(&self, t0: Instant) {
        eprintln!(
            "fmi_fuzz: {} calls ({} fmi2OK, {} refused), slowest {:.1} ms, {:.1} s",
            self.calls.load(Ordering::Relaxed),
            self.ok.load(Ordering::Relaxed),
            self.refused.load(Ordering::Relaxed),
            self.slowest_us.load(Ordering::Relaxed) as f64 / 1e3,
            t0.elapsed().as_secs_f64()
        );
        let per: Vec<String> = wheelflat::fmu::CALLS
            .iter()
            .map(|(c, name, _)| {
                let [n, ok] = &self.per_call[*c as usize];
                format!(
                    "{name} {}/{}",
                    ok.load(Ordering::Relaxed),
                    n.load(Ordering::Relaxed)
                )
            })
            .collect();
        eprintln!("fmi_fuzz: fmi2OK/calls: {}", per.join(", "));
    }
}
