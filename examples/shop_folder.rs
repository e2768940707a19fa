//! Writes the GENERATED shop-style demo folder (the demo's pos-a tests as a control's TNCscope
//! traces in machine coordinates and R-Test logger files with a metadata line and a units row,
//! paired by one `[[pairing]]`; see `tests/common/shop.rs` and
//! `measurements/demo-vmc-shop/README.md`):
//! `cargo run --release --example shop_folder -- measurements/demo-vmc-shop`. Files of the
//! folder the generator does not write (an older layout's) are left for you to remove.

#[allow(dead_code)] // the Sinumerik variant is for a test
#[path = "../tests/common/shop.rs"]
mod shop;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .ok_or("usage: cargo run --release --example shop_folder -- DIR")?;
    let dir = std::path::Path::new(&dir);
    let pos_a =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("measurements/demo-vmc/pos-a");
    for (name, bytes) in shop::files(&pos_a) {
        let path = dir.join(&name);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)?;
        }
        std::fs::write(&path, bytes)?;
    }
    println!("wrote {}", dir.display());
    Ok(())
}
