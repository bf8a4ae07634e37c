//! What a run did: calls, OK and refusals per function of either FMI version, the
//! slowest call.

use crate::fmi3_calls::{F3, F3S};
use std::ffi::c_int;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;
use wheelflat::fmu::{CALLS, Call};

/// Statistics of a run.
pub struct Stats {
    pub calls: AtomicUsize,
    pub ok: AtomicUsize,
    pub refused: AtomicUsize,
    pub slowest_us: AtomicUsize,
    /// Per function (the index of [`Call`], then [`CALLS`]'s length plus the index of
    /// [`F3`]): calls, OK.
    pub per_call: [[AtomicUsize; 2]; CALLS.len() + F3S.len()],
}

impl Stats {
    /// A call of the FMI 2.0 function `call` that returned `status`.
    pub fn count(&self, call: Call, status: c_int) {
        self.count_at(call as usize, status)
    }

    /// A call of the FMI 3.0 function `f` that returned `status`.
    pub fn count3(&self, f: F3, status: c_int) {
        self.count_at(CALLS.len() + f as usize, status)
    }

    fn count_at(&self, k: usize, status: c_int) {
        self.calls.fetch_add(1, Ordering::Relaxed);
        self.per_call[k][0].fetch_add(1, Ordering::Relaxed);
        if status == 0 {
            self.per_call[k][1].fetch_add(1, Ordering::Relaxed);
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
            "fmi_fuzz: {} calls ({} OK, {} refused), slowest {:.1} ms, {:.1} s",
            self.calls.load(Ordering::Relaxed),
            self.ok.load(Ordering::Relaxed),
            self.refused.load(Ordering::Relaxed),
            self.slowest_us.load(Ordering::Relaxed) as f64 / 1e3,
            t0.elapsed().as_secs_f64()
        );
        let names = CALLS.iter().map(|c| c.1).chain(F3S.iter().map(|f| f.1));
        let per: Vec<String> = names
            .zip(&self.per_call)
            .filter(|(_, [n, _])| n.load(Ordering::Relaxed) > 0)
            .map(|(name, [n, ok])| {
                format!(
                    "{name} {}/{}",
                    ok.load(Ordering::Relaxed),
                    n.load(Ordering::Relaxed)
                )
            })
            .collect();
        eprintln!("fmi_fuzz: OK/calls: {}", per.join(", "));
    }
}
