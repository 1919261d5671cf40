//! The thesis, side by side (`docs/thesis.md`): prints the measured tables;
//! `cargo run --release --example thesis -- --write` also puts them into the document.

mod tables;

fn main() {
    let tables = tables::tables();
    print!("{tables}");
    if std::env::args().any(|a| a == "--write") {
        let path = "docs/thesis.md";
        let document = std::fs::read_to_string(path).expect("docs/thesis.md");
        let updated = tables::with_tables(&document, &tables).expect("docs/thesis.md has the table markers");
        std::fs::write(path, updated).expect("write docs/thesis.md");
        eprintln!("wrote the tables into {path}");
    }
}
