//! Packs the three FMUs: `fmu/<modelIdentifier>.fmu` with the generated
//! modelDescription.xml and the crate's shared library as
//! `binaries/<platform>/<modelIdentifier>.so`; writes the C header of the exported
//! functions to `fmu/include/wheelflat_fmi2.h`.
//!
//! Run after `cargo build --release` (the shared library must sit next to this
//! executable): `cargo build --release && cargo run --release --bin build_fmus [OUT_DIR
//! [VARIABLES.md]]`; the second argument writes the variables' documentation generated
//! from the table there (`docs/VARIABLES.md`).

use std::io::Write;
use std::path::{Path, PathBuf};
use wheelflat::fmu::vars::{C_HEADER, FMUS, VARIABLES_MD};
use zip::write::SimpleFileOptions;

#[cfg(all(target_os = "linux", target_arch = "x86_64"))]
const PLATFORM: (&str, &str, &str) = ("linux64", "libwheelflat.so", "so");
#[cfg(all(target_os = "linux", target_arch = "aarch64"))]
const PLATFORM: (&str, &str, &str) = ("aarch64-linux", "libwheelflat.so", "so");
#[cfg(target_os = "macos")]
const PLATFORM: (&str, &str, &str) = ("darwin64", "libwheelflat.dylib", "dylib");
#[cfg(target_os = "windows")]
const PLATFORM: (&str, &str, &str) = ("win64", "wheelflat.dll", "dll");

fn main() {
    if let Err(e) = run() {
        eprintln!("build_fmus: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let out: PathBuf = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("fmu"));
    let exe = std::env::current_exe()?;
    let lib = exe
        .parent()
        .ok_or("executable has no directory")?
        .join(PLATFORM.1);
    let binary = std::fs::read(&lib).map_err(|e| {
        format!(
            "cannot read the shared library {}: {e}; build it first with `cargo build --release`",
            lib.display()
        )
    })?;
    // A second argument: where to write the variables' documentation.
    if let Some(doc) = std::env::args().nth(2) {
        std::fs::write(&doc, VARIABLES_MD)?;
        println!("{doc} (from the variable table)");
    }
    std::fs::create_dir_all(out.join("include"))?;
    std::fs::write(out.join("include/wheelflat_fmi2.h"), C_HEADER)?;
    for t in FMUS {
        let path = out.join(format!("{}.fmu", t.model_identifier));
        let file = std::fs::File::create(&path)?;
        let mut z = zip::ZipWriter::new(file);
        let opts =
            SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        z.start_file("modelDescription.xml", opts)?;
        z.write_all(t.model_description.as_bytes())?;
        z.start_file(
            format!(
                "binaries/{}/{}.{}",
                PLATFORM.0, t.model_identifier, PLATFORM.2
            ),
            opts.unix_permissions(0o755),
        )?;
        z.write_all(&binary)?;
        z.start_file("documentation/index.html", opts)?;
        z.write_all(
            format!(
                "<html><body><h1>{}</h1><p>wheelflat {}: see README.md of the wheelflat \
                 repository for variables, coupling and validation.</p></body></html>\n",
                t.model_identifier,
                env!("CARGO_PKG_VERSION")
            )
            .as_bytes(),
        )?;
        z.finish()?;
        println!("{} ({} {})", path.display(), t.model_identifier, t.guid);
    }
    Ok(())
}
