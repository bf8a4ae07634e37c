//! Build script: turns the one variable table `modelDescription/variables.xml` into
//! - `$OUT_DIR/<modelIdentifier>.xml`, the modelDescription.xml of each FMU, with a
//!   GUID derived from its content ([`model_description`]), and
//!   `$OUT_DIR/fmi3/<modelIdentifier>.xml`, its FMI 3.0 model description ([`fmi3`]);
//! - `$OUT_DIR/variables.rs`, the Rust table of the same variables (value references,
//!   types, causalities, ranges, start values) that the FMI layer reads and writes
//!   ([`rust_binding`]);
//! - `$OUT_DIR/VARIABLES.md`, the variables' documentation ([`variables_md`];
//!   `docs/VARIABLES.md` is this file, committed: a unit test fails when it is stale,
//!   and `cargo run --release --bin build_fmus -- fmu docs/VARIABLES.md` rewrites it);
//! - `$OUT_DIR/documentation/<modelIdentifier>.html`, each FMU's
//!   `documentation/index.html`: what the model is, its variables, how to couple it and
//!   its limits, from the prose of `build/pages/` and the table ([`documentation`]);
//!   `$OUT_DIR/documentation.rs` lists them for `build_fmus`, which packs them;
//! - `$OUT_DIR/wheelflat_fmi2.h` and `$OUT_DIR/wheelflat_fmi3.h`, the C headers of the
//!   exported FMI 2.0 and FMI 3.0 functions, by cbindgen ([`c_header`]).
//!
//! [`table`] reads and checks the table; each generator is one file of this folder.

mod c_header;
mod documentation;
mod fmi3;
mod model_description;
mod rust_binding;
mod table;
mod variables_md;

use std::env;
use std::fs;
use std::path::PathBuf;
use table::{TABLE, Table};

fn main() {
    println!("cargo:rerun-if-changed={TABLE}");
    for src in c_header::FMI2.ffi.iter().chain(c_header::FMI3.ffi) {
        println!("cargo:rerun-if-changed={src}");
    }
    println!("cargo:rerun-if-changed=build");
    let out = PathBuf::from(env::var("OUT_DIR").unwrap());
    let version = env::var("CARGO_PKG_VERSION").unwrap();
    let text = fs::read_to_string(TABLE).expect("read modelDescription/variables.xml");
    let table = Table::read(&text);

    let mut guids = Vec::new();
    for fmu in &table.fmus {
        let (md, guid) = model_description::write(&table, fmu, &version);
        fs::write(out.join(format!("{}.xml", fmu.id())), md).unwrap();
        guids.push(guid);
    }
    fs::create_dir_all(out.join("fmi3")).unwrap();
    let mut tokens = Vec::new();
    for fmu in &table.fmus {
        let (md, token) = fmi3::write(&table, fmu, &version);
        fs::write(out.join(format!("fmi3/{}.xml", fmu.id())), md).unwrap();
        tokens.push(token);
    }
    fs::write(
        out.join("variables.rs"),
        rust_binding::write(&table, &guids) + &fmi3::rust(&table, &tokens),
    )
    .unwrap();
    fs::write(out.join("VARIABLES.md"), variables_md::write(&table)).unwrap();
    fs::create_dir_all(out.join("documentation")).unwrap();
    for (fmu, guid) in table.fmus.iter().zip(&guids) {
        fs::write(
            out.join(format!("documentation/{}.html", fmu.id())),
            documentation::write(&table, fmu, guid, &version),
        )
        .unwrap();
    }
    fs::write(out.join("documentation.rs"), documentation::index(&table)).unwrap();
    c_header::write(&c_header::FMI2, &out.join("wheelflat_fmi2.h"));
    c_header::write(&c_header::FMI3, &out.join("wheelflat_fmi3.h"));
}
