//! Writes the diagnosis demo set (generated circle tests with known ballbar errors, see
//! `tests/common/diagnosis_demo.rs`): `cargo run --release --example diagnosis_demo -- DIR`.

#[path = "../tests/common/circle_terms.rs"]
mod circle_terms;
#[path = "../tests/common/diagnosis_demo.rs"]
mod diagnosis_demo;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .ok_or("usage: cargo run --release --example diagnosis_demo -- DIR")?;
    let dir = std::path::Path::new(&dir);
    std::fs::create_dir_all(dir)?;
    for (name, bytes) in diagnosis_demo::files() {
        std::fs::write(dir.join(&name), bytes)?;
        println!("wrote {}", dir.join(name).display());
    }
    Ok(())
}
