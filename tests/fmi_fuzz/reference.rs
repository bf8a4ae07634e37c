//! The reference instance: driven by a fixed valid sequence between the random calls,
//! it must give bit for bit what the same sequence gives alone.

use crate::common::{Log, callbacks};
use crate::{CALLS_PER_SEQUENCE, REF_H};
use std::ffi::CString;
use std::sync::OnceLock;
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::vars::{Causality, FMUS, FmuTable, VarType};

/// An instance driven by a fixed valid sequence: one step of `REF_H` and all Real
/// outputs read, per call of [`Reference::advance`].
pub struct Reference {
    c: fmi2Component,
    _log: Box<Log>,
    outs: Vec<u32>,
    k: usize,
    pub record: Vec<Vec<u64>>,
}

impl Reference {
    pub fn new(table: &'static FmuTable) -> Reference {
        let log = Box::<Log>::default();
        let cb = callbacks(&log);
        let guid = CString::new(table.guid).unwrap();
        let c = unsafe {
            fmi2Instantiate(
                c"reference".as_ptr(),
                1,
                guid.as_ptr(),
                c"".as_ptr(),
                &cb,
                0,
                0,
            )
        };
        assert!(!c.is_null());
        unsafe {
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
            assert_eq!(fmi2EnterInitializationMode(c), 0);
            assert_eq!(fmi2ExitInitializationMode(c), 0);
        }
        let outs = table
            .vars
            .iter()
            .filter(|v| v.causality == Causality::Output && v.ty == VarType::Real)
            .map(|v| v.vr)
            .collect();
        Reference {
            c,
            _log: log,
            outs,
            k: 0,
            record: Vec::new(),
        }
    }

    pub fn advance(&mut self) {
        let t = self.k as f64 * REF_H;
        let mut v = vec![0.0; self.outs.len()];
        unsafe {
            assert_eq!(
                fmi2DoStep(self.c, t, REF_H, 1),
                0,
                "reference step {}",
                self.k
            );
            assert_eq!(
                fmi2GetReal(self.c, self.outs.as_ptr(), self.outs.len(), v.as_mut_ptr()),
                0
            );
        }
        self.record.push(v.iter().map(|x| x.to_bits()).collect());
        self.k += 1;
    }
}

impl Drop for Reference {
    fn drop(&mut self) {
        unsafe { fmi2FreeInstance(self.c) };
    }
}

/// The reference sequence of each FMU run alone.
pub fn alone() -> &'static [Vec<Vec<u64>>; 3] {
    static ALONE: OnceLock<[Vec<Vec<u64>>; 3]> = OnceLock::new();
    ALONE.get_or_init(|| {
        [0, 1, 2].map(|k| {
            let mut r = Reference::new(FMUS[k]);
            for _ in 0..CALLS_PER_SEQUENCE {
                r.advance();
            }
            std::mem::take(&mut r.record)
        })
    })
}
