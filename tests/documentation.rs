//! Each FMU's documentation/index.html (build/documentation.rs) quotes the limits of
//! `src/limits.rs` as they are: a bound changed there fails here until the page's prose
//! (`build/pages/`) says the new number. The variables' rows are checked against the
//! packed FMUs by `tests/test_fmu_descriptions.py`.

use wheelflat::fmu::vars::FMUS;
use wheelflat::limits::*;

mod pages {
    include!(concat!(env!("OUT_DIR"), "/documentation.rs"));
}

fn page(id: &str) -> &'static str {
    pages::DOCUMENTATION
        .iter()
        .find(|(i, _)| *i == id)
        .unwrap_or_else(|| panic!("no page for {id}"))
        .1
}

/// Millimetres of a length in metres, as the pages write them.
fn mm(x: f64) -> String {
    format!("{} mm", (x * 1e3 * 1e9).round() / 1e9)
}

#[test]
fn every_fmu_has_a_page_naming_it_and_its_guid() {
    assert_eq!(pages::DOCUMENTATION.len(), FMUS.len());
    for t in FMUS {
        let p = page(t.model_identifier);
        assert!(p.contains(&format!("<h1>{}</h1>", t.model_identifier)));
        assert!(p.contains(t.guid));
        for v in t.vars {
            assert!(
                p.contains(&format!("<code>{}</code>", v.name)),
                "{}",
                v.name
            );
        }
    }
}

#[test]
fn the_pages_quote_the_bounds_of_src_limits() {
    let track = [
        format!("{:e} rail-node updates", MAX_NODE_STEPS_PER_CALL),
        format!("at most {:e} rail segments", MAX_RAIL_SEGMENTS as f64),
        format!(
            "{FORCE_LIMIT_FACTOR} times the static wheel load (at least {} MN)",
            FORCE_LIMIT_FACTOR * FORCE_LIMIT_MIN_STATIC_LOAD / 1e6
        ),
        format!("under the wheels\nagainst {DISPLACEMENT_LIMIT} m"),
        format!("every {HEALTH_CHECK_INTERVAL} steps every rail node and sleeper"),
        format!("overlap above {}", mm(MAX_STATIC_OVERLAP)),
        format!("rail deflection above {}", mm(MAX_STATIC_RAIL_DEFLECTION)),
        format!("a flat deeper than {}", mm(MAX_FLAT_DEPTH)),
        format!("between {MIN_DT_FRACTION:e} and 1 times the critical step"),
    ];
    let vehicle = [
        format!("{:e} vehicle steps", MAX_VEHICLE_STEPS_PER_CALL),
        format!("the bodies against {BODY_DISPLACEMENT_LIMIT} m"),
        format!("more than {MAX_STATIC_DEFLECTION} m"),
        format!("shorter than {MIN_STEP_FRACTION:e} of its"),
        format!("between {MIN_DT_FRACTION:e} and 0.5 times its critical step"),
    ];
    for (id, quotes) in [
        ("TrackContact", &track[..]),
        ("CoupledSystem", &track[..]),
        ("RollPlaneVehicle", &vehicle[..]),
    ] {
        // The prose wraps lines; compare with single spaces.
        let text = page(id).split_whitespace().collect::<Vec<_>>().join(" ");
        for q in quotes {
            let q = q.split_whitespace().collect::<Vec<_>>().join(" ");
            assert!(text.contains(&q), "{id}: the page does not say {q:?}");
        }
    }
}
