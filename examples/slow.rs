use eij::control::ClosedLoop;
use eij::machine::Machine;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let m = Machine::from_file(std::path::Path::new(&args[1])).unwrap();
    let cl = ClosedLoop::new(&m, &m.reference_pose()).unwrap();
    let mut ev = cl.eigenvalues().unwrap();
    ev.sort_by(|a, b| b.re.total_cmp(&a.re));
    for e in ev.iter().take(8) {
        println!("{:12.4} {:12.4}", e.re, e.im);
    }
}
