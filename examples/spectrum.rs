use eij::machine::Machine;
use eij::mbs::{modal, Model};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let m = Machine::from_file(std::path::Path::new(&args[1])).unwrap();
    let pose: Vec<f64> = args[2..].iter().map(|s| s.parse().unwrap()).collect();
    let model = Model::assemble(&m, &pose).unwrap();
    for md in modal::modes(&model).unwrap() {
        println!(
            "{:10.3} {:12} {:.2}",
            md.frequency_hz, md.dominant_dof, md.dominant_share
        );
    }
}
