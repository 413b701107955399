#[path = "../tests/common/table1.rs"]
mod table1;
fn main() {
    let s = table1::system();
    let s2 = table1::system_with_resolution(2401);
    for (x, y) in [(-0.375, -27.5), (-0.3725, -27.5), (-0.4, -27.5), (-0.35,-27.5)] {
        println!("e {x} ec {y}: infer {} dense {} r2401 {}", s.infer(&[x, y]).unwrap(), s.infer_dense(&[x, y], 100_001).unwrap(), s2.infer(&[x,y]).unwrap());
    }
    // Monotonicity with dense reference along e at ec=-27.5
    let mut prev = f64::NEG_INFINITY; let mut worst = 0.0f64;
    for i in 0..=180 { let x = -0.45 + 0.9*i as f64/180.0; let u = s.infer_dense(&[x, -27.5], 20_001).unwrap(); worst = worst.max(prev - u); prev = u; }
    println!("dense worst decrease along e at ec=-27.5: {worst}");
    let mut prev = f64::NEG_INFINITY; let mut worst = 0.0f64;
    for i in 0..=120 { let y = -30.0 + 60.0*i as f64/120.0; let u = s.infer_dense(&[-0.415, y], 20_001).unwrap(); worst = worst.max(prev - u); prev = u; }
    println!("dense worst decrease along ec at e=-0.415: {worst}");
    for i in 0..=12 { let y = -30.0 + 1.0*i as f64; let t = s.infer_traced(&[-0.415, y]).unwrap(); println!("ec {y}: u {} strengths {:?}", t.output, t.term_strengths); }
}
