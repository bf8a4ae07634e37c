//! Making one FMI 2.0 call: its arguments from [`crate::args`], the call under the
//! watchdog, and the checks of what it returns (outputs finite with fmi2OK, booleans 0
//! or 1). FMI 3.0's is [`crate::fmi3_dispatch`].

use crate::args::{boolean, faulty_value, nasty, refs, spec, step_size, value_for};
use crate::fmu_state::StateOp;
use crate::world::World;
use rand::Rng;
use std::ffi::c_int;
use std::time::Duration;
use wheelflat::fmu::Call;
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::vars::{FmuTable, VarType};

impl World {
    /// Makes the call; returns its status, description and duration.
    pub fn dispatch(
        &mut self,
        call: Call,
        i: usize,
        c: fmi2Component,
        table: &'static FmuTable,
        name: &str,
    ) -> (c_int, String, Duration) {
        let rng = &mut self.rng;
        let valid = self.valid;
        let null_ptr = !valid && rng.random_ratio(1, 25);
        match call {
            Call::GetTypesPlatform | Call::GetVersion => {
                let (p, d) = self.timed(format!("{name}: {}()", call.name()), || {
                    if call == Call::GetTypesPlatform {
                        fmi2GetTypesPlatform()
                    } else {
                        fmi2GetVersion()
                    }
                });
                assert!(!p.is_null());
                (0, call.name().into(), d)
            }
            Call::SetDebugLogging => {
                let on = boolean(rng, valid);
                let names = [
                    c"logStatusError",
                    c"logStatusWarning",
                    c"logCalls",
                    c"logEvents",
                    c"noSuchCategory",
                ];
                let n = rng.random_range(0..4);
                let mut cats: Vec<fmi2String> = (0..n)
                    .map(|_| names[rng.random_range(0..names.len())].as_ptr())
                    .collect();
                if null_ptr && n > 0 {
                    cats[0] = std::ptr::null();
                }
                let nulled = rng.random_ratio(1, 30);
                run!(
                    self,
                    name,
                    format!("fmi2SetDebugLogging({on}, {n} categories)"),
                    fmi2SetDebugLogging(
                        c,
                        on,
                        n,
                        if nulled {
                            std::ptr::null()
                        } else {
                            cats.as_ptr()
                        }
                    )
                )
            }
            Call::SetupExperiment => {
                let (td, sd) = (boolean(rng, valid), boolean(rng, valid));
                let start = if valid || rng.random_bool(0.9) {
                    0.0
                } else {
                    nasty(rng)
                };
                let stop = match rng.random_range(0..4) {
                    0 if !valid => nasty(rng),
                    0 | 1 => rng.random_range(0.001..2.0),
                    _ => 1.0,
                };
                run!(
                    self,
                    name,
                    format!("fmi2SetupExperiment({td}, 1e-6, {start:?}, {sd}, {stop:?})"),
                    fmi2SetupExperiment(c, td, 1e-6, start, sd, stop)
                )
            }
            Call::EnterInitializationMode => {
                run!(
                    self,
                    name,
                    "fmi2EnterInitializationMode()",
                    fmi2EnterInitializationMode(c)
                )
            }
            Call::ExitInitializationMode => {
                run!(
                    self,
                    name,
                    "fmi2ExitInitializationMode()",
                    fmi2ExitInitializationMode(c)
                )
            }
            Call::Terminate => run!(self, name, "fmi2Terminate()", fmi2Terminate(c)),
            Call::Reset => {
                let r = run!(self, name, "fmi2Reset()", fmi2Reset(c));
                if r.0 == 0 {
                    self.slots[i].t = 0.0;
                }
                r
            }
            Call::GetReal | Call::GetInteger | Call::GetBoolean | Call::GetString => {
                let vrs = if call == Call::GetReal && rng.random_bool(0.2) {
                    table
                        .vars
                        .iter()
                        .filter(|v| v.ty == VarType::Real)
                        .map(|v| v.vr)
                        .collect()
                } else {
                    refs(
                        rng,
                        table,
                        Some(if call == Call::GetReal {
                            VarType::Real
                        } else {
                            VarType::Integer
                        }),
                        valid,
                    )
                };
                let n = vrs.len();
                let vp = if null_ptr {
                    std::ptr::null()
                } else {
                    vrs.as_ptr()
                };
                let null_out = !valid && rng.random_ratio(1, 25);
                let desc = format!("{}(vr={vrs:?})", call.name());
                match call {
                    Call::GetReal => {
                        let mut out = vec![0.0f64; n];
                        let op = if null_out {
                            std::ptr::null_mut()
                        } else {
                            out.as_mut_ptr()
                        };
                        let r = run!(self, name, desc, fmi2GetReal(c, vp, n, op));
                        if r.0 == 0
                            && let Some(k) = out.iter().position(|x| !x.is_finite())
                        {
                            let v = spec(table, vrs[k]).map_or("?", |v| v.name);
                            self.fail(format!(
                                "{}: fmi2GetReal returned fmi2OK with `{v}` = {}",
                                r.1, out[k]
                            ));
                        }
                        r
                    }
                    Call::GetInteger => {
                        let mut out = vec![0 as c_int; n];
                        let op = if null_out {
                            std::ptr::null_mut()
                        } else {
                            out.as_mut_ptr()
                        };
                        run!(self, name, desc, fmi2GetInteger(c, vp, n, op))
                    }
                    Call::GetBoolean => {
                        let mut out = vec![0 as c_int; n];
                        let op = if null_out {
                            std::ptr::null_mut()
                        } else {
                            out.as_mut_ptr()
                        };
                        run!(self, name, desc, fmi2GetBoolean(c, vp, n, op))
                    }
                    _ => {
                        let mut out = vec![std::ptr::null::<i8>(); n];
                        let op = if null_out {
                            std::ptr::null_mut()
                        } else {
                            out.as_mut_ptr()
                        };
                        run!(self, name, desc, fmi2GetString(c, vp, n, op))
                    }
                }
            }
            Call::SetReal | Call::SetInteger | Call::SetBoolean | Call::SetString => {
                let want = if call == Call::SetReal {
                    VarType::Real
                } else {
                    VarType::Integer
                };
                let vrs = refs(rng, table, Some(want), valid);
                let n = vrs.len();
                let vp = if null_ptr {
                    std::ptr::null()
                } else {
                    vrs.as_ptr()
                };
                let null_in = !valid && rng.random_ratio(1, 25);
                let vals: Vec<f64> = vrs
                    .iter()
                    .map(|&r| value_for(rng, spec(table, r), valid))
                    .collect();
                match call {
                    Call::SetReal => {
                        let ip = if null_in {
                            std::ptr::null()
                        } else {
                            vals.as_ptr()
                        };
                        run!(
                            self,
                            name,
                            format!("fmi2SetReal(vr={vrs:?}, value={vals:?})"),
                            fmi2SetReal(c, vp, n, ip)
                        )
                    }
                    Call::SetInteger => {
                        let ints: Vec<c_int> = vals
                            .iter()
                            .map(|&x| {
                                if !valid && rng.random_ratio(1, 10) {
                                    [c_int::MIN, c_int::MAX, -1, 0][rng.random_range(0..4)]
                                } else {
                                    x as c_int
                                }
                            })
                            .collect();
                        // Integer parameters go through the same fault filter.
                        let ints: Vec<c_int> = ints
                            .iter()
                            .zip(&vrs)
                            .map(|(&x, &r)| match spec(table, r) {
                                Some(v) if faulty_value(v, x as f64) => v.start as c_int,
                                _ => x,
                            })
                            .collect();
                        let ip = if null_in {
                            std::ptr::null()
                        } else {
                            ints.as_ptr()
                        };
                        run!(
                            self,
                            name,
                            format!("fmi2SetInteger(vr={vrs:?}, value={ints:?})"),
                            fmi2SetInteger(c, vp, n, ip)
                        )
                    }
                    Call::SetBoolean => {
                        let bools: Vec<c_int> = (0..n).map(|_| boolean(rng, valid)).collect();
                        let ip = if null_in {
                            std::ptr::null()
                        } else {
                            bools.as_ptr()
                        };
                        run!(
                            self,
                            name,
                            format!("fmi2SetBoolean(vr={vrs:?}, value={bools:?})"),
                            fmi2SetBoolean(c, vp, n, ip)
                        )
                    }
                    _ => {
                        let strs: Vec<fmi2String> = (0..n)
                            .map(|k| {
                                if k == 0 && null_in {
                                    std::ptr::null()
                                } else {
                                    c"text".as_ptr()
                                }
                            })
                            .collect();
                        run!(
                            self,
                            name,
                            format!("fmi2SetString(vr={vrs:?})"),
                            fmi2SetString(c, vp, n, strs.as_ptr())
                        )
                    }
                }
            }
            Call::GetFMUstate => self.state_call(StateOp::Get, i, c, name, null_ptr),
            Call::SetFMUstate => self.state_call(StateOp::Set, i, c, name, null_ptr),
            Call::FreeFMUstate => self.state_call(StateOp::Free, i, c, name, null_ptr),
            Call::SerializedFMUstateSize => self.state_call(StateOp::Size, i, c, name, null_ptr),
            Call::SerializeFMUstate => self.state_call(StateOp::Serialize, i, c, name, null_ptr),
            Call::DeSerializeFMUstate => {
                self.state_call(StateOp::Deserialize, i, c, name, null_ptr)
            }
            Call::GetDirectionalDerivative => {
                let v = [0u32];
                let mut o = [0.0];
                run!(
                    self,
                    name,
                    "fmi2GetDirectionalDerivative()",
                    fmi2GetDirectionalDerivative(
                        c,
                        v.as_ptr(),
                        1,
                        v.as_ptr(),
                        1,
                        o.as_ptr(),
                        o.as_mut_ptr()
                    )
                )
            }
            Call::SetRealInputDerivatives => {
                let v = [0u32];
                let ord = [1];
                let x = [0.0];
                run!(
                    self,
                    name,
                    "fmi2SetRealInputDerivatives()",
                    fmi2SetRealInputDerivatives(c, v.as_ptr(), 1, ord.as_ptr(), x.as_ptr())
                )
            }
            Call::GetRealOutputDerivatives => {
                let v = [0u32];
                let ord = [1];
                let mut x = [0.0];
                run!(
                    self,
                    name,
                    "fmi2GetRealOutputDerivatives()",
                    fmi2GetRealOutputDerivatives(c, v.as_ptr(), 1, ord.as_ptr(), x.as_mut_ptr())
                )
            }
            Call::DoStep => {
                let t = if valid || rng.random_bool(0.85) {
                    self.slots[i].t
                } else {
                    nasty(rng)
                };
                let h = step_size(rng, valid);
                let b = if rng.random_bool(0.9) {
                    rng.random_range(0..2)
                } else {
                    boolean(rng, valid)
                };
                let r = run!(
                    self,
                    name,
                    format!("fmi2DoStep(t={t:?}, h={h:?}, noSet={b})"),
                    fmi2DoStep(c, t, h, b)
                );
                if r.0 == 0 {
                    self.slots[i].t = t + h;
                }
                r
            }
            Call::CancelStep => run!(self, name, "fmi2CancelStep()", fmi2CancelStep(c)),
            Call::GetStatus => {
                let mut s = 0;
                run!(self, name, "fmi2GetStatus(0)", fmi2GetStatus(c, 0, &mut s))
            }
            Call::GetRealStatus => {
                let k = rng.random_range(0..5);
                let mut x = 0.0;
                run!(
                    self,
                    name,
                    format!("fmi2GetRealStatus({k})"),
                    fmi2GetRealStatus(
                        c,
                        k,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            &mut x
                        }
                    )
                )
            }
            Call::GetIntegerStatus => {
                let mut x = 0;
                run!(
                    self,
                    name,
                    "fmi2GetIntegerStatus(0)",
                    fmi2GetIntegerStatus(c, 0, &mut x)
                )
            }
            Call::GetBooleanStatus => {
                let k = rng.random_range(0..5);
                let mut x = 0;
                let r = run!(
                    self,
                    name,
                    format!("fmi2GetBooleanStatus({k})"),
                    fmi2GetBooleanStatus(
                        c,
                        k,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            &mut x
                        }
                    )
                );
                if r.0 == 0 && x != 0 && x != 1 {
                    self.fail(format!("{}: not an fmi2Boolean: {x}", r.1));
                }
                r
            }
            Call::GetStringStatus => {
                let mut x: fmi2String = std::ptr::null();
                run!(
                    self,
                    name,
                    "fmi2GetStringStatus(0)",
                    fmi2GetStringStatus(c, 0, &mut x)
                )
            }
            Call::Instantiate | Call::FreeInstance => unreachable!(),
        }
    }
}
