use eij::control::ClosedLoop;
use eij::machine::Machine;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let m = Machine::from_file(std::path::Path::new(&args[1])).unwrap();
    let pose = m.reference_pose();
    match ClosedLoop::new(&m, &pose) {
        Ok(cl) => {
            let mut ev = cl.eigenvalues().unwrap();
            ev.sort_by(|a, b| (b.re / b.norm()).total_cmp(&(a.re / a.norm())));
            for e in ev.iter().take(12) {
                println!(
                    "{:10.2} {:10.2}  f={:8.2} Hz zeta={:.3}",
                    e.re,
                    e.im,
                    e.norm() / 6.2832,
                    -e.re / e.norm()
                );
            }
        }
        Err(e) => println!("ERR {e}"),
    }
}
