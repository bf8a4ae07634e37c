//! The FMI 3.0 calls these units refuse whatever the instance's phase: the gets and
//! sets of the types no variable has (an empty request succeeds, any value reference is
//! refused; the values are never touched), and the functions of Model Exchange,
//! Scheduled Execution, Event Mode, clocks and per-element dependencies (fmi3Error, or
//! no instance, with the reason; nothing but the instance is read, so they are given
//! null pointers and counts their buffers do not have too).

use crate::common::record3;
use crate::fmi3_args::{TIME_VR, refs3};
use crate::fmi3_calls::F3;
use crate::fmi3_dispatch::{Made, env, or_null, or_null_mut};
use crate::world::World;
use rand::Rng;
use std::ffi::{CString, c_int};
use wheelflat::fmu::ffi3::*;
use wheelflat::fmu::vars::Type3;

impl World {
    /// A get or set of Float32, Int8, UInt8, Int16, UInt16, UInt32, Boolean or Binary
    /// on instance `i` (instance pointer `c`, named `name`).
    pub fn absent_type(
        &mut self,
        f: F3,
        i: usize,
        c: fmi3Instance,
        name: &str,
        null_ptr: bool,
    ) -> Made {
        let table = self.slots[i].table3;
        let rng = &mut self.rng;
        let any = [
            Type3::Float64,
            Type3::Int32,
            Type3::Enumeration,
            Type3::String,
            Type3::Wheelsets,
            Type3::Constant,
        ];
        let vrs: Vec<u32> = match rng.random_range(0..5) {
            0 => Vec::new(),
            1 | 2 => refs3(rng, table, &any, true, false),
            3 => vec![TIME_VR],
            _ => vec![u32::MAX, 0],
        };
        let nv = rng.random_range(0..4);
        let null_values = rng.random_bool(0.2);
        let desc = format!("{}(vr={vrs:?}, nValues={nv})", f.name());
        macro_rules! get {
            ($ffi:expr, $fill:expr) => {{
                let (r, out) =
                    self.get_values(desc, name, c, &vrs, nv, $fill, $ffi, null_ptr, null_values);
                (r, out.iter().all(|x| *x == $fill))
            }};
        }
        macro_rules! set {
            ($ffi:expr, $fill:expr) => {{
                let v = vec![$fill; nv];
                let r = self.set_values(desc, name, c, &vrs, &v, $ffi, null_ptr, null_values);
                (r, true)
            }};
        }
        let (r, untouched) = match f {
            F3::GetFloat32 => get!(fmi3GetFloat32, 0.5f32),
            F3::SetFloat32 => set!(fmi3SetFloat32, 0.5f32),
            F3::GetInt8 => get!(fmi3GetInt8, 7i8),
            F3::SetInt8 => set!(fmi3SetInt8, 7i8),
            F3::GetUInt8 => get!(fmi3GetUInt8, 7u8),
            F3::SetUInt8 => set!(fmi3SetUInt8, 7u8),
            F3::GetInt16 => get!(fmi3GetInt16, 7i16),
            F3::SetInt16 => set!(fmi3SetInt16, 7i16),
            F3::GetUInt16 => get!(fmi3GetUInt16, 7u16),
            F3::SetUInt16 => set!(fmi3SetUInt16, 7u16),
            F3::GetUInt32 => get!(fmi3GetUInt32, 7u32),
            F3::SetUInt32 => set!(fmi3SetUInt32, 7u32),
            F3::GetBoolean => get!(fmi3GetBoolean, true),
            F3::SetBoolean => set!(fmi3SetBoolean, true),
            F3::GetBinary => {
                let mut sizes = vec![7usize; nv];
                let mut values = vec![std::ptr::null::<u8>(); nv];
                let r = run!(
                    self,
                    name,
                    desc,
                    fmi3GetBinary(
                        c,
                        or_null(null_ptr, vrs.as_ptr()),
                        vrs.len(),
                        or_null_mut(null_values, sizes.as_mut_ptr()),
                        values.as_mut_ptr(),
                        nv
                    )
                );
                let untouched = sizes.iter().all(|&s| s == 7) && values.iter().all(|p| p.is_null());
                (r, untouched)
            }
            _ => {
                let bytes = [1u8, 2, 3];
                let sizes = vec![3usize; nv];
                let values = vec![bytes.as_ptr(); nv];
                let r = run!(
                    self,
                    name,
                    desc,
                    fmi3SetBinary(
                        c,
                        or_null(null_ptr, vrs.as_ptr()),
                        vrs.len(),
                        or_null(null_values, sizes.as_ptr()),
                        values.as_ptr(),
                        nv
                    )
                );
                (r, true)
            }
        };
        if !untouched {
            self.fail(format!(
                "{}: the values of a type no variable has were written",
                r.1
            ));
        }
        r
    }

    /// A function of Model Exchange, Scheduled Execution, Event Mode, clocks or
    /// per-element dependencies on instance `i` (instance pointer `c`, named `name`):
    /// small buffers, or null pointers with `null_ptr`.
    pub fn refused(
        &mut self,
        f: F3,
        i: usize,
        c: fmi3Instance,
        name: &str,
        null_ptr: bool,
    ) -> Made {
        let rng = &mut self.rng;
        let n = rng.random_range(0..4usize);
        let vr = [0u32, 1, 2, TIME_VR];
        let vp = or_null(null_ptr, vr.as_ptr());
        let (mut x, mut y, mut z) = ([0.0f64; 4], [0u64; 4], [0u64; 4]);
        let (mut q, mut b, mut k) = ([0 as c_int; 4], [false; 6], [0usize; 4]);
        let (xp, yp, zp) = (
            or_null_mut(null_ptr, x.as_mut_ptr()),
            or_null_mut(null_ptr, y.as_mut_ptr()),
            or_null_mut(null_ptr, z.as_mut_ptr()),
        );
        let (qp, bp, kp) = (
            or_null_mut(null_ptr, q.as_mut_ptr()),
            or_null_mut(null_ptr, b.as_mut_ptr()),
            or_null_mut(null_ptr, k.as_mut_ptr()),
        );
        let bn = |j: usize| if bp.is_null() { bp } else { bp.wrapping_add(j) };
        let desc = format!(
            "{}(count {n}{})",
            f.name(),
            if null_ptr { ", null pointers" } else { "" }
        );
        if matches!(
            f,
            F3::InstantiateModelExchange | F3::InstantiateScheduledExecution
        ) {
            let token = CString::new(self.slots[i].table3.token).unwrap();
            let e = env(&self.slots[i].log);
            let (p, d) = self.timed(format!("{name}: {desc}"), || unsafe {
                if f == F3::InstantiateModelExchange {
                    fmi3InstantiateModelExchange(
                        c"me".as_ptr(),
                        token.as_ptr(),
                        std::ptr::null(),
                        false,
                        true,
                        e,
                        Some(record3),
                    )
                } else {
                    fmi3InstantiateScheduledExecution(
                        c"se".as_ptr(),
                        token.as_ptr(),
                        std::ptr::null(),
                        false,
                        true,
                        e,
                        Some(record3),
                        std::ptr::null(),
                        std::ptr::null(),
                        std::ptr::null(),
                    )
                }
            });
            if !p.is_null() {
                self.fail(format!("{desc}: made an instance"));
            }
            return (3, desc, d);
        }
        let t = x[0] + 0.25;
        match f {
            F3::EnterEventMode => run!(self, name, desc, fmi3EnterEventMode(c)),
            F3::EnterStepMode => run!(self, name, desc, fmi3EnterStepMode(c)),
            F3::EvaluateDiscreteStates => run!(self, name, desc, fmi3EvaluateDiscreteStates(c)),
            F3::UpdateDiscreteStates => run!(
                self,
                name,
                desc,
                fmi3UpdateDiscreteStates(c, bn(0), bn(1), bn(2), bn(3), bn(4), xp)
            ),
            F3::GetNumberOfVariableDependencies => run!(
                self,
                name,
                desc,
                fmi3GetNumberOfVariableDependencies(c, vr[n], kp)
            ),
            F3::GetVariableDependencies => run!(
                self,
                name,
                desc,
                fmi3GetVariableDependencies(c, vr[n], kp, qp as *mut u32, kp, qp, n)
            ),
            F3::GetClock => run!(self, name, desc, fmi3GetClock(c, vp, n, bp)),
            F3::SetClock => run!(self, name, desc, fmi3SetClock(c, vp, n, bp)),
            F3::GetIntervalDecimal => {
                run!(self, name, desc, fmi3GetIntervalDecimal(c, vp, n, xp, qp))
            }
            F3::GetIntervalFraction => run!(
                self,
                name,
                desc,
                fmi3GetIntervalFraction(c, vp, n, yp, zp, qp)
            ),
            F3::GetShiftDecimal => run!(self, name, desc, fmi3GetShiftDecimal(c, vp, n, xp)),
            F3::GetShiftFraction => run!(self, name, desc, fmi3GetShiftFraction(c, vp, n, yp, zp)),
            F3::SetIntervalDecimal => run!(self, name, desc, fmi3SetIntervalDecimal(c, vp, n, xp)),
            F3::SetIntervalFraction => {
                run!(self, name, desc, fmi3SetIntervalFraction(c, vp, n, yp, zp))
            }
            F3::SetShiftDecimal => run!(self, name, desc, fmi3SetShiftDecimal(c, vp, n, xp)),
            F3::SetShiftFraction => run!(self, name, desc, fmi3SetShiftFraction(c, vp, n, yp, zp)),
            F3::EnterContinuousTimeMode => run!(self, name, desc, fmi3EnterContinuousTimeMode(c)),
            F3::CompletedIntegratorStep => run!(
                self,
                name,
                desc,
                fmi3CompletedIntegratorStep(c, true, bn(0), bn(1))
            ),
            F3::SetTime => run!(self, name, desc, fmi3SetTime(c, t)),
            F3::SetContinuousStates => run!(self, name, desc, fmi3SetContinuousStates(c, xp, n)),
            F3::GetContinuousStateDerivatives => run!(
                self,
                name,
                desc,
                fmi3GetContinuousStateDerivatives(c, xp, n)
            ),
            F3::GetEventIndicators => run!(self, name, desc, fmi3GetEventIndicators(c, xp, n)),
            F3::GetContinuousStates => run!(self, name, desc, fmi3GetContinuousStates(c, xp, n)),
            F3::GetNominalsOfContinuousStates => run!(
                self,
                name,
                desc,
                fmi3GetNominalsOfContinuousStates(c, xp, n)
            ),
            F3::GetNumberOfEventIndicators => {
                run!(self, name, desc, fmi3GetNumberOfEventIndicators(c, kp))
            }
            F3::GetNumberOfContinuousStates => {
                run!(self, name, desc, fmi3GetNumberOfContinuousStates(c, kp))
            }
            F3::ActivateModelPartition => {
                run!(self, name, desc, fmi3ActivateModelPartition(c, vr[n], t))
            }
            _ => unreachable!("{} is not refused", f.name()),
        }
    }
}
