//! The documentation's Rust blocks, run as doctests: each page is the doc comment of an
//! empty item here, so `cargo test --doc` compiles and runs its blocks from the crate root.
//! `tests/docs.rs` checks that every page with Rust blocks is listed.

/// Defines one empty item per page, documented by that page.
macro_rules! pages {
    ($($item:ident: $file:literal,)*) => {
        $(
            #[doc = include_str!($file)]
            pub struct $item;
        )*
    };
}

pages! {
    Readme: "../README.md",
    DocsIndex: "../docs/README.md",
    Cli: "../docs/cli.md",
    Compiled: "../docs/compiled.md",
    Contributing: "../docs/contributing.md",
    Fidelity: "../docs/fidelity.md",
    Install: "../docs/install.md",
    Limits: "../docs/limits.md",
    ModelHierarchy: "../docs/model-hierarchy.md",
    Scenes: "../docs/scenes.md",
    Speed: "../docs/speed.md",
}
