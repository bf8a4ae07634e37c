//! The reference instance, of either FMI version: driven by a fixed valid sequence
//! between the random calls, it must give bit for bit what the same sequence gives
//! alone.

use crate::common::{Log, callbacks, record3};
use crate::world::Version;
use crate::{CALLS_PER_SEQUENCE, REF_H};
use std::ffi::{CString, c_void};
use std::sync::OnceLock;
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::ffi3::*;
use wheelflat::fmu::vars::{Causality, FMI3_FMUS, FMUS, N_VR, Type3, VarType};

/// The wheelsets an FMI 3.0 reference instance of an FMU with the structural parameter
/// `wheelsets` is configured to (arrays of two elements).
const REF_WHEELSETS: u64 = 2;

/// An instance driven by a fixed valid sequence: one step of `REF_H` and all Real
/// (Float64) outputs read, per call of [`Reference::advance`]. The FMI 3.0 one is
/// configured to [`REF_WHEELSETS`] where it can be and reads `time` too.
pub struct Reference {
    c: *mut c_void,
    version: Version,
    _log: Box<Log>,
    outs: Vec<u32>,
    /// The number of values `outs` have.
    n_values: usize,
    k: usize,
    pub record: Vec<Vec<u64>>,
}

impl Reference {
    pub fn new(version: Version, kind: usize) -> Reference {
        match version {
            Version::Fmi2 => Reference::new2(kind),
            Version::Fmi3 => Reference::new3(kind),
        }
    }

    fn new2(kind: usize) -> Reference {
        let table = FMUS[kind];
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
        let outs: Vec<u32> = table
            .vars
            .iter()
            .filter(|v| v.causality == Causality::Output && v.ty == VarType::Real)
            .map(|v| v.vr)
            .collect();
        Reference {
            c,
            version: Version::Fmi2,
            _log: log,
            n_values: outs.len(),
            outs,
            k: 0,
            record: Vec::new(),
        }
    }

    fn new3(kind: usize) -> Reference {
        let table = FMI3_FMUS[kind];
        let log = Box::<Log>::default();
        let token = CString::new(table.token).unwrap();
        let c = unsafe {
            fmi3InstantiateCoSimulation(
                c"reference".as_ptr(),
                token.as_ptr(),
                c"".as_ptr(),
                false,
                false,
                false,
                false,
                std::ptr::null(),
                0,
                &*log as *const Log as *mut c_void,
                Some(record3),
                std::ptr::null(),
            )
        };
        assert!(!c.is_null(), "{}", log.text());
        let mut wheelsets = crate::fmi3_args::start_wheelsets(table);
        if let Some(w) = table.vars.iter().find(|v| v.ty == Type3::Wheelsets) {
            unsafe {
                assert_eq!(fmi3EnterConfigurationMode(c), 0, "{}", log.text());
                assert_eq!(
                    fmi3SetUInt64(c, &w.vr, 1, &REF_WHEELSETS, 1),
                    0,
                    "{}",
                    log.text()
                );
                assert_eq!(fmi3ExitConfigurationMode(c), 0, "{}", log.text());
            }
            wheelsets = REF_WHEELSETS as usize;
        }
        unsafe {
            assert_eq!(
                fmi3EnterInitializationMode(c, false, 0.0, 0.0, false, 0.0),
                0,
                "{}",
                log.text()
            );
            assert_eq!(fmi3ExitInitializationMode(c), 0, "{}", log.text());
        }
        let mut outs: Vec<u32> = table
            .vars
            .iter()
            .filter(|v| v.causality == "output" && v.ty == Type3::Float64)
            .map(|v| v.vr)
            .collect();
        outs.push(N_VR as u32);
        let n_values = crate::fmi3_args::values_of(table, &outs, wheelsets);
        Reference {
            c,
            version: Version::Fmi3,
            _log: log,
            outs,
            n_values,
            k: 0,
            record: Vec::new(),
        }
    }

    pub fn advance(&mut self) {
        let t = self.k as f64 * REF_H;
        let mut v = vec![0.0; self.n_values];
        let (c, outs, k) = (self.c, &self.outs, self.k);
        unsafe {
            match self.version {
                Version::Fmi2 => {
                    assert_eq!(fmi2DoStep(c, t, REF_H, 1), 0, "reference step {k}");
                    assert_eq!(fmi2GetReal(c, outs.as_ptr(), outs.len(), v.as_mut_ptr()), 0);
                }
                Version::Fmi3 => {
                    let (mut event, mut end, mut early, mut last) = (false, false, false, 0.0);
                    let s = fmi3DoStep(
                        c, t, REF_H, true, &mut event, &mut end, &mut early, &mut last,
                    );
                    assert_eq!(s, 0, "reference step {k}: {}", self._log.last());
                    let s = fmi3GetFloat64(c, outs.as_ptr(), outs.len(), v.as_mut_ptr(), v.len());
                    assert_eq!(s, 0, "{}", self._log.last());
                }
            }
        }
        self.record.push(v.iter().map(|x| x.to_bits()).collect());
        self.k += 1;
    }
}

impl Drop for Reference {
    fn drop(&mut self) {
        match self.version {
            Version::Fmi2 => unsafe { fmi2FreeInstance(self.c) },
            Version::Fmi3 => unsafe { fmi3FreeInstance(self.c) },
        }
    }
}

/// The reference sequence of FMU `kind` of `version` run alone (made once, by the
/// first sequence that needs it).
pub fn alone(version: Version, kind: usize) -> &'static [Vec<u64>] {
    type Records = Vec<OnceLock<Vec<Vec<u64>>>>;
    static ALONE: OnceLock<Records> = OnceLock::new();
    let all = ALONE.get_or_init(|| (0..2 * FMUS.len()).map(|_| OnceLock::new()).collect());
    let at = kind
        + if version == Version::Fmi3 {
            FMUS.len()
        } else {
            0
        };
    all[at].get_or_init(|| {
        let mut r = Reference::new(version, kind);
        for _ in 0..CALLS_PER_SEQUENCE {
            r.advance();
        }
        std::mem::take(&mut r.record)
    })
}
