//! The house as ARCHITECTURE.md describes it: its first table names every
//! workspace member (path, wing, machine, what it holds) with the package
//! each folder builds, a member's wing is the folder it stands in, and the
//! rules every crate keeps (the workspace's unsafe lints, the rustdoc link
//! lint on) hold in every member.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../..")
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The workspace's members as the root Cargo.toml lists them.
fn members() -> Vec<String> {
    let manifest: toml::Value = toml::from_str(&read(&root().join("Cargo.toml"))).unwrap();
    manifest["workspace"]["members"]
        .as_array()
        .expect("workspace.members")
        .iter()
        .map(|m| m.as_str().expect("a path").to_string())
        .collect()
}

/// A row of ARCHITECTURE.md's first table.
struct Row {
    path: String,
    package: String,
    wing: String,
    machine: String,
    holds: String,
}

/// The rows of the first table under `## Crates`.
fn crate_table() -> Vec<Row> {
    let text = read(&root().join("ARCHITECTURE.md"));
    let from = text.find("\n## Crates").expect("a '## Crates' section");
    let table = text[from..]
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .collect::<Vec<_>>();
    assert_eq!(
        table[0].trim(),
        "| path | wing | machine | what it holds |",
        "the table's columns"
    );
    table[2..]
        .iter()
        .map(|line| {
            let cells: Vec<&str> = line.trim_matches('|').split(" | ").map(str::trim).collect();
            assert_eq!(cells.len(), 4, "four cells in {line:?}");
            let quoted: Vec<&str> = cells[0].split('`').skip(1).step_by(2).collect();
            assert!(quoted.len() >= 2, "`path` (`package`) in {line:?}");
            Row {
                path: quoted[0].to_string(),
                package: quoted[1].to_string(),
                wing: cells[1].to_string(),
                machine: cells[2].to_string(),
                holds: cells[3].to_string(),
            }
        })
        .collect()
}

#[test]
fn the_first_table_names_every_member_once_with_its_package_and_wing() {
    let rows = crate_table();
    let named: Vec<&str> = rows.iter().map(|r| r.path.as_str()).collect();
    let unique: BTreeSet<&str> = named.iter().copied().collect();
    assert_eq!(unique.len(), named.len(), "a member named twice: {named:?}");
    let members = members();
    let listed: BTreeSet<&str> = members.iter().map(String::as_str).collect();
    assert_eq!(
        unique, listed,
        "ARCHITECTURE.md's first table against Cargo.toml's members"
    );
    for row in &rows {
        let manifest: toml::Value =
            toml::from_str(&read(&root().join(&row.path).join("Cargo.toml"))).unwrap();
        assert_eq!(
            manifest["package"]["name"].as_str(),
            Some(row.package.as_str()),
            "{}: the package the table names",
            row.path
        );
        // crates/WING/CRATE: the wing column says the folder's name in words.
        let parts: Vec<&str> = row.path.split('/').collect();
        assert_eq!(parts.len(), 3, "{}: crates/WING/CRATE", row.path);
        assert_eq!(
            row.wing,
            parts[1].replace('-', " "),
            "{}: its wing",
            row.path
        );
        assert!(
            !row.machine.is_empty() && !row.holds.is_empty(),
            "{}: filled in",
            row.path
        );
    }
}

#[test]
fn every_member_keeps_the_workspace_lints_and_the_doc_link_lint() {
    let manifest: toml::Value = toml::from_str(&read(&root().join("Cargo.toml"))).unwrap();
    let lints = &manifest["workspace"]["lints"];
    assert_eq!(
        lints["rust"]["unsafe_op_in_unsafe_fn"].as_str(),
        Some("deny")
    );
    assert_eq!(
        lints["clippy"]["undocumented_unsafe_blocks"].as_str(),
        Some("deny")
    );
    for member in members() {
        let dir = root().join(&member);
        let own: toml::Value = toml::from_str(&read(&dir.join("Cargo.toml"))).unwrap();
        assert_eq!(
            own.get("lints")
                .and_then(|l| l.get("workspace"))
                .and_then(toml::Value::as_bool),
            Some(true),
            "{member}: [lints] workspace = true"
        );
        let mut stack = vec![dir.join("src")];
        while let Some(at) = stack.pop() {
            for entry in std::fs::read_dir(&at).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    stack.push(path);
                } else if path.extension().is_some_and(|e| e == "rs") {
                    assert!(
                        !read(&path).contains("allow(rustdoc::broken_intra_doc_links"),
                        "{}: units are written (m), so the link lint stays on",
                        path.display()
                    );
                }
            }
        }
    }
}

/// The dependencies a member's Cargo.toml names (normal ones, by package).
fn dependencies(member: &str) -> (String, Vec<String>) {
    let own: toml::Value = toml::from_str(&read(&root().join(member).join("Cargo.toml"))).unwrap();
    let name = own["package"]["name"].as_str().unwrap().to_string();
    let deps = own
        .get("dependencies")
        .and_then(toml::Value::as_table)
        .map(|t| t.keys().cloned().collect())
        .unwrap_or_default();
    (name, deps)
}

#[test]
fn the_figures_reach_no_opc_ua_stack() {
    // The workspace's graph from the members' manifests; the figures'
    // closure over it, and every dependency that closure names.
    let graph: std::collections::BTreeMap<String, Vec<String>> =
        members().iter().map(|m| dependencies(m)).collect();
    let mut seen = BTreeSet::new();
    let mut stack = vec!["autoshovel-figures".to_string()];
    while let Some(name) = stack.pop() {
        if !seen.insert(name.clone()) {
            continue;
        }
        if let Some(deps) = graph.get(&name) {
            stack.extend(deps.iter().cloned());
        }
    }
    for banned in ["autoshovel-plc-link", "async-opcua", "tokio"] {
        assert!(
            !seen.contains(banned),
            "autoshovel-figures reaches {banned}: {seen:?}"
        );
    }
    // The run log it writes the shift's record with is in reach.
    assert!(seen.contains("autoshovel-run-log"));
}

#[test]
fn benchmarks_is_one_page_that_opens_on_the_side_by_side_table() {
    let text = read(&root().join("BENCHMARKS.md"));
    let lines = text.lines().count();
    assert!(
        lines <= 400,
        "BENCHMARKS.md has {lines} lines; the history goes to docs/benchmarks-log.md"
    );
    let first_table = text.lines().find(|l| l.starts_with('|')).expect("a table");
    assert!(
        first_table.contains("ours") && first_table.contains("peers"),
        "the first table is ours beside the peers: {first_table}"
    );
    assert!(root().join("docs/benchmarks-log.md").is_file());
}
