//! Which FMU a loaded binary is, and which GUIDs it instantiates.

use super::component::c_str;
use crate::fmu::Kind;
use std::ffi::c_void;

/// The FMU a binary belongs to, from its file name: FMI 2.0 names the shared library
/// `binaries/<platform>/<modelIdentifier>.<ext>`, so the stem is the model identifier.
/// `None` for any other name (the development library `libwheelflat.so`, a test
/// executable that links the crate).
pub fn kind_of_binary(path: &str) -> Option<Kind> {
    let stem = std::path::Path::new(path).file_stem()?.to_str()?;
    Kind::ALL
        .into_iter()
        .find(|k| k.table().model_identifier == stem)
}

/// A byte of this binary's own data: its address lies in this loaded object whatever
/// the loader. (The address of an exported function does not: a host that loads several
/// FMU libraries with `RTLD_GLOBAL` resolves an exported name to the first library
/// loaded, so `dladdr` on it named that library for all of them.) Not exported, so every
/// reference to it binds inside this object.
static ANCHOR: u8 = 0;

/// Path of the loaded object that holds this code (the FMU's shared library, or the
/// executable that links the crate), from the dynamic loader.
///
/// Asked at every `fmi2Instantiate` rather than cached: a cached copy would outlive an
/// unloaded library (a leak per `dlopen`/`dlclose`).
pub fn loaded_binary() -> Option<String> {
    #[cfg(unix)]
    {
        let mut info: libc::Dl_info = unsafe { std::mem::zeroed() };
        let addr = std::hint::black_box(&ANCHOR) as *const u8 as *const c_void;
        if unsafe { libc::dladdr(addr, &mut info) } != 0 && !info.dli_fname.is_null() {
            return c_str(info.dli_fname);
        }
        None
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// The FMU a GUID instantiates in a binary of `binary` (see [`kind_of_binary`]): only
/// its own GUID when the binary is one FMU's, any of the four otherwise.
pub fn kind_for_guid(binary: Option<Kind>, guid: &str) -> Result<Kind, String> {
    let found = Kind::from_guid(guid);
    match (binary, found) {
        (None, Some(k)) => Ok(k),
        (Some(b), Some(k)) if b == k => Ok(k),
        (Some(b), Some(k)) => Err(format!(
            "GUID \"{guid}\" belongs to {}, but this binary is {} (GUID {}): instantiate {} \
             from its own FMU",
            k.table().model_identifier,
            b.table().model_identifier,
            b.table().guid,
            k.table().model_identifier
        )),
        (Some(b), None) => Err(format!(
            "GUID \"{guid}\" matches none of the wheelflat FMUs; this binary is {} (GUID {})",
            b.table().model_identifier,
            b.table().guid
        )),
        (None, None) => Err(format!(
            "GUID \"{guid}\" matches none of {}",
            Kind::ALL
                .map(|k| format!("{} ({})", k.table().model_identifier, k.table().guid))
                .join(", ")
        )),
    }
}
