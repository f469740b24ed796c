//! docs/validation.md's summary tables are the tool's own: the block between its markers equals
//! what `geartherm validate validation --doc docs/validation.md` writes for today's code and
//! cases.

use std::path::PathBuf;

use geartherm::job::validate::{validate, ValidateOptions};
use geartherm::report::validation::{doc_block, doc_block_of, splice_doc, DOC_BEGIN, DOC_END};

#[test]
fn the_committed_tables_are_the_tools() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let r = validate(&ValidateOptions {
        dir: root.join("validation"),
    })
    .unwrap();
    let expected = doc_block(&r.rows, &r.summary);
    let doc = std::fs::read_to_string(root.join("docs/validation.md")).unwrap();
    let committed = doc_block_of(&doc).expect("docs/validation.md has the markers");
    assert!(
        committed == expected,
        "docs/validation.md is stale: run `geartherm validate validation --out plots/validation --doc docs/validation.md`\n\
         committed:\n{committed}\ntool:\n{expected}"
    );
}

#[test]
fn splicing_replaces_only_the_block() {
    let doc = format!("intro\n{DOC_BEGIN}\nold\n{DOC_END}\noutro\n");
    let new = splice_doc(&doc, "new\n").unwrap();
    assert_eq!(new, format!("intro\n{DOC_BEGIN}\nnew\n{DOC_END}\noutro\n"));
    assert_eq!(doc_block_of(&new), Some("new\n"));
    assert!(splice_doc("no markers", "x").is_err());
}
