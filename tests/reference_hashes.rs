//! The same bits on every reference run (issue 42: speed work changes no result): the
//! sample hashes of `tools/sample_hash.rs` (`cargo run --release --example
//! sample_hash`) against those recorded when the rail between nodes became a beam
//! (issue 27) and, for the thesis' linear interpolation (3.23), against every run
//! before it; and the wagon on the default window, as it was before issue 42's speed
//! work on the wheelsets it shares. The vector levels (AVX2, AVX-512, both with FMA)
//! give these bits; the baseline rounds every product of the track loops and agrees to
//! rounding only, so the check needs FMA.

#[path = "../tools/sample_hash.rs"]
mod sample_hash;

use wheelflat::numerics::SimdLevel;

#[test]
fn every_reference_run_keeps_its_bits() {
    if SimdLevel::detect() == SimdLevel::Baseline {
        eprintln!("no FMA on this CPU: the recorded bits are the vector levels'");
        return;
    }
    let want = [
        (
            "seed grid (n = 2, dt = 45 us), 0.8 s",
            0xa0db33b5ccb1389a_u64,
            17778,
        ),
        (
            "seed grid (n = 2, dt = 45 us), 0.8 s, linear (3.23)",
            0xca87e4a538843d11,
            17778,
        ),
        ("converged defaults, 0.3 s", 0x66bba26e2fa77542, 20814),
        (
            "converged defaults, 0.3 s, linear (3.23)",
            0xfd1aed06ca0dd1f1,
            20814,
        ),
        ("three more flats, 0.3 s", 0xf90595911b7eceed, 20814),
        (
            "three more flats, 0.3 s, linear (3.23)",
            0xe173932efd4e3ca6,
            20814,
        ),
        // Recorded at the start of issue 42's work (d6a1225).
        ("the wagon, default window, 0.1 s", 0xb8e99d2f1ce049f4, 6938),
    ];
    let got = sample_hash::hashes(None);
    assert_eq!(got.len(), want.len());
    for ((name, h, n), (wname, wh, wn)) in got.iter().zip(want) {
        assert_eq!((name.as_str(), *n), (wname, wn));
        assert_eq!(*h, wh, "{name}: sample hash {h:016x}, recorded {wh:016x}");
    }
}
