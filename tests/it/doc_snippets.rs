//! Every scene snippet in README.md and docs/*.md parses, validates and compiles (issue 17 §2),
//! so the docs cannot show a field, a kind or an asset the renderer no longer accepts.
//!
//! The snippets are the fenced blocks whose info string starts with `ron` or `toml`:
//!
//! - ```` ```ron ```` / ```` ```toml ````: a whole scene file.
//! - ```` ```ron fragment ```` / ```` ```toml fragment ````: top-level fields of a scene (for
//!   example `textures: {…}, materials: {…},`), spliced into a minimal scene that adds a camera,
//!   a `materials` table if the fragment has none, and one sphere per material (so every
//!   material, and every texture a material names, is compiled and its files loaded). RON:
//!   `Scene(camera: …, nodes: […],` on the first line, then the fragment from line 2, then `)`.
//!   TOML: the fragment first (its own line numbers), then the camera and node tables.
//!
//! Each snippet is checked as if it were a file in `scenes/`: relative paths resolve from there,
//! as in the demo scenes, and every `file` a snippet names must be a file the repository ships.
//! Validation warnings are allowed; errors fail the test with the document's name and line.

use std::path::{Path, PathBuf};

use caustic::compile::compile;
use caustic::scene::SourceFile;
use caustic::scene::validate::validate;

use crate::common;

/// A fenced scene block of a Markdown file.
#[derive(Debug)]
struct Snippet {
    /// The Markdown file.
    doc: PathBuf,
    /// Line of the opening fence (1-based).
    line: usize,
    /// `ron` or `toml`.
    lang: String,
    /// Marked `fragment`.
    fragment: bool,
    /// The block's text.
    text: String,
}

impl Snippet {
    fn at(&self) -> String {
        format!(
            "{}:{} (```{}{} block)",
            self.doc
                .strip_prefix(common::root())
                .unwrap_or(&self.doc)
                .display(),
            self.line,
            self.lang,
            if self.fragment { " fragment" } else { "" }
        )
    }
}

/// README.md and every docs/*.md.
fn docs() -> Vec<PathBuf> {
    let mut v = vec![common::root().join("README.md")];
    let mut more: Vec<PathBuf> = std::fs::read_dir(common::root().join("docs"))
        .expect("docs/ exists")
        .map(|e| e.expect("dir entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "md"))
        .collect();
    more.sort();
    v.extend(more);
    v
}

/// The `ron` and `toml` fenced blocks of `doc`.
fn snippets(doc: &Path) -> Vec<Snippet> {
    let text = std::fs::read_to_string(doc).unwrap_or_else(|e| panic!("{}: {e}", doc.display()));
    let mut out = Vec::new();
    let mut open: Option<(usize, String, bool, Vec<&str>)> = None;
    for (i, line) in text.lines().enumerate() {
        match (&mut open, line.strip_prefix("```")) {
            (None, Some(info)) => {
                let mut words = info.split_whitespace();
                let lang = words.next().unwrap_or_default().to_string();
                let rest: Vec<&str> = words.collect();
                assert!(
                    rest.is_empty() || rest == ["fragment"],
                    "{}:{}: unknown fence annotation {rest:?} (only `fragment` is known)",
                    doc.display(),
                    i + 1
                );
                open = Some((i + 1, lang, !rest.is_empty(), Vec::new()));
            }
            (Some(_), Some(_)) => {
                let (line, lang, fragment, body) = open.take().expect("open block");
                if lang == "ron" || lang == "toml" {
                    out.push(Snippet {
                        doc: doc.to_path_buf(),
                        line,
                        lang,
                        fragment,
                        text: body.join("\n") + "\n",
                    });
                }
            }
            (Some((_, _, _, body)), None) => body.push(line),
            (None, None) => {}
        }
    }
    assert!(open.is_none(), "{}: unclosed code block", doc.display());
    out
}

/// Whether the fragment sets the top-level field `materials` itself.
fn has_materials(s: &Snippet) -> bool {
    s.text.lines().any(|l| {
        let l = l.trim_start();
        if s.lang == "ron" {
            l.starts_with("materials:")
        } else {
            l.starts_with("[materials]")
        }
    })
}

/// The fragment spliced into a minimal scene whose nodes are one sphere for each of
/// `materials`.
fn splice(s: &Snippet, materials: &[String]) -> String {
    let own = has_materials(s);
    if s.lang == "ron" {
        let nodes: Vec<String> = materials
            .iter()
            .enumerate()
            .map(|(i, m)| {
                format!(
                    "Sphere(material: {m:?}, center: ({}, 0, 0), radius: 0.5)",
                    i * 2
                )
            })
            .collect();
        let extra = if own {
            ""
        } else {
            r#"materials: { "grey": () }, "#
        };
        format!(
            "Scene(camera: Pinhole(eye: (0, 0, 10), look_at: (0, 0, 0), fov_y: 40), {extra}nodes: [{}],\n{})\n",
            nodes.join(", "),
            s.text
        )
    } else {
        let mut t = s.text.clone();
        if !own {
            t.push_str("\n[materials]\ngrey = {}\n");
        }
        t.push_str("\n[camera.Pinhole]\neye = [0, 0, 10]\nlook_at = [0, 0, 0]\nfov_y = 40\n");
        if materials.is_empty() {
            t.push_str("nodes = []\n");
        }
        for (i, m) in materials.iter().enumerate() {
            t.push_str(&format!(
                "\n[[nodes]]\nSphere = {{ material = {m:?}, center = [{}, 0, 0], radius = 0.5 }}\n",
                i * 2
            ));
        }
        t
    }
}

/// Parses, validates and compiles `text` as the file `scenes/<name>`; an error names `at`.
fn check_scene(at: &str, name: &str, text: String) -> caustic::scene::SceneFile {
    let path = common::root().join("scenes").join(name);
    let source = SourceFile::new(&path, text.clone()).unwrap_or_else(|e| panic!("{at}: {e}"));
    let scene = source
        .parse()
        .unwrap_or_else(|e| panic!("{at}: does not parse: {e}\n--- as checked:\n{text}"));
    let errors: Vec<String> = validate(&scene)
        .into_iter()
        .filter(caustic::scene::Diagnostic::is_error)
        .map(|d| format!("{d:?}"))
        .collect();
    assert!(
        errors.is_empty(),
        "{at}: does not validate: {errors:#?}\n--- as checked:\n{text}"
    );
    if let Err(errors) = compile(&scene, &source.base_dir()) {
        panic!("{at}: does not compile: {errors:#?}\n--- as checked:\n{text}");
    }
    scene
}

/// Every `file: "…"` (RON) or `file = "…"` (TOML) of a snippet names a file the repository
/// ships, relative to `scenes/`.
fn check_files(s: &Snippet) {
    let key = if s.lang == "ron" { "file:" } else { "file =" };
    for part in s.text.split(key).skip(1) {
        let name = part
            .trim_start()
            .strip_prefix('"')
            .and_then(|p| p.split('"').next());
        let Some(name) = name else { continue };
        let path = common::root().join("scenes").join(name);
        assert!(
            path.is_file(),
            "{}: names `{name}`, which the repository does not ship (resolved from scenes/: {})",
            s.at(),
            path.display()
        );
    }
}

/// Checks one snippet; returns the materials it compiled.
fn check_snippet(s: &Snippet) -> usize {
    check_files(s);
    let name = format!("snippet.{}", s.lang);
    if !s.fragment {
        return check_scene(&s.at(), &name, s.text.clone()).materials.len();
    }
    // First pass: the fragment's materials (no nodes yet), then one sphere for each.
    let first = check_scene_parse_only(&s.at(), &name, splice(s, &[]));
    let materials: Vec<String> = first.materials.keys().cloned().collect();
    check_scene(&s.at(), &name, splice(s, &materials));
    materials.len()
}

/// Parses (only) `text` as the file `scenes/<name>`.
fn check_scene_parse_only(at: &str, name: &str, text: String) -> caustic::scene::SceneFile {
    let path = common::root().join("scenes").join(name);
    SourceFile::new(&path, text.clone())
        .and_then(|s| s.parse())
        .unwrap_or_else(|e| panic!("{at}: does not parse: {e}\n--- as checked:\n{text}"))
}

#[test]
fn every_scene_snippet_in_the_docs_parses_validates_and_compiles() {
    let mut checked = Vec::new();
    for doc in docs() {
        for s in snippets(&doc) {
            let materials = check_snippet(&s);
            checked.push(format!("{} ({materials} materials)", s.at()));
        }
    }
    eprintln!("checked: {checked:#?}");
    // README.md has a whole scene and a fragment, docs/textures.md a fragment.
    assert!(checked.len() >= 3, "too few snippets found: {checked:#?}");
}

/// The checker is not a rubber stamp: a misspelt field, a missing asset and a bad value in a
/// snippet each fail it.
#[test]
fn a_broken_snippet_fails() {
    let good = "textures: { \"wood\": Bitmap(file: \"../assets/hardwood.png\") },\n\
                materials: { \"floor\": (color: \"wood\") },\n";
    let snippet = |text: &str| Snippet {
        doc: common::root().join("README.md"),
        line: 1,
        lang: "ron".into(),
        fragment: true,
        text: text.into(),
    };
    assert_eq!(check_snippet(&snippet(good)), 1);
    for bad in [
        good.replace("color:", "colour:"),
        good.replace("hardwood.png", "duck.png"),
        good.replace("(color: \"wood\")", "(color: \"wood\", ior: -1.5)"),
        good.replace("(color: \"wood\")", "(color: \"oak\")"),
    ] {
        let caught = std::panic::catch_unwind(|| check_snippet(&snippet(&bad)));
        assert!(caught.is_err(), "accepted a broken snippet:\n{bad}");
    }
}

/// The commands in README.md's "The two commands" section: the ```sh blocks, one line each.
fn readme_commands() -> Vec<String> {
    let text = std::fs::read_to_string(common::root().join("README.md")).expect("README.md");
    let section = text
        .split("\n## ")
        .find(|s| s.starts_with("The two commands"))
        .expect("README.md has a \"The two commands\" section");
    section
        .split("```sh\n")
        .skip(1)
        .filter_map(|block| block.split("```").next())
        .flat_map(str::lines)
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .map(str::to_string)
        .collect()
}

/// CI runs the README's test command (with `--locked`), so the figures beside it are CI's too.
#[test]
fn ci_runs_the_readme_test_command() {
    let commands = readme_commands();
    assert_eq!(commands.len(), 2, "{commands:?}");
    assert!(
        commands[0].starts_with("cargo run --release -- render "),
        "{commands:?}"
    );
    let ci = std::fs::read_to_string(common::root().join(".ci/run")).expect(".ci/run");
    let want = format!("{} --locked", commands[1]);
    assert!(
        ci.lines().any(|l| l.trim() == want),
        ".ci/run does not run the README's test command as `{want}`"
    );
}
