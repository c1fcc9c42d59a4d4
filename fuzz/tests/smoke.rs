//! A CI-sized fuzz run: 2,000 inputs of each target with a fixed seed, no panic allowed. The
//! million-input runs are `cargo run --profile fuzz -p yat-fuzz -- parser|wire` (README.md).

use std::time::Duration;

use yat_fuzz::campaign::{self, Settings};
use yat_fuzz::parser_target::{ParserTarget, SeedFolders};
use yat_fuzz::wire_target::WireTarget;
use yat_fuzz::workspace::workspace_root;

const INPUTS: u64 = 2_000;

fn settings() -> Settings {
    Settings {
        inputs: INPUTS,
        seed: 19,
        crash_dir: None,
        slow: Duration::from_secs(10),
        progress_every: 0,
        minimize_for: Duration::from_secs(5),
    }
}

#[test]
fn parser_inputs_never_panic() {
    let root = workspace_root();
    // The project's own scenes and the snippets only: the same corpus on every machine.
    let mut target = ParserTarget::new(&SeedFolders {
        scenes: vec![root.join("scenes")],
        snippets: Some(root.join("fuzz/corpus")),
    })
    .unwrap();
    assert!(target.seed_count() >= 15, "{} seeds", target.seed_count());
    let report = campaign::run(&mut target, &settings());
    print!("{report}");
    assert_eq!(report.inputs, INPUTS);
    assert!(report.findings.is_empty(), "panics: {:#?}", report.findings);
    // A good share of the inputs get past the parser, so the build and render are fuzzed too.
    assert!(report.accepted * 3 >= INPUTS, "{report}");
}

#[test]
fn wire_inputs_never_panic() {
    let report = campaign::run(&mut WireTarget::new(), &settings());
    print!("{report}");
    assert_eq!(report.inputs, INPUTS);
    assert!(report.findings.is_empty(), "{report}");
}
