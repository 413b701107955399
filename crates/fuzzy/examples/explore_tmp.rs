#[path = "../tests/common/table1.rs"]
mod table1;
fn main() {
    let s = table1::system();
    // monotonicity in e
    let (nx, ny) = (361, 121);
    let mut worst_e = 0.0f64; let mut at_e = (0.0, 0.0);
    let mut worst_ec = 0.0f64; let mut at_ec = (0.0, 0.0);
    let xs: Vec<f64> = (0..nx).map(|i| -0.45 + 0.9 * i as f64 / (nx - 1) as f64).collect();
    let ys: Vec<f64> = (0..ny).map(|i| -30.0 + 60.0 * i as f64 / (ny - 1) as f64).collect();
    let z: Vec<Vec<f64>> = ys.iter().map(|&y| xs.iter().map(|&x| s.infer(&[x, y]).unwrap()).collect()).collect();
    for iy in 0..ny { for ix in 1..nx { let d = z[iy][ix-1] - z[iy][ix]; if d > worst_e { worst_e = d; at_e = (xs[ix], ys[iy]); } } }
    for ix in 0..nx { for iy in 1..ny { let d = z[iy-1][ix] - z[iy][ix]; if d > worst_ec { worst_ec = d; at_ec = (xs[ix], ys[iy]); } } }
    println!("max decrease along e: {worst_e} at {at_e:?}; along ec: {worst_ec} at {at_ec:?}");
    for res in [201, 181, 241, 401] {
        let s = table1::system_with_resolution(res);
        let mut w = 0.0f64; let mut at = (0.0,0.0);
        for i in 0..41 { for j in 0..41 {
            let x = -0.45 + 0.9 * i as f64 / 40.0; let y = -30.0 + 60.0 * j as f64 / 40.0;
            let d = (s.infer(&[x,y]).unwrap() - s.infer_dense(&[x,y], 100_001).unwrap()).abs();
            if d > w { w = d; at = (x,y); }
        }}
        println!("res {res}: max |infer - dense| = {w} at {at:?}");
    }
    let d1 = s.infer_dense(&[0.1, 3.0], 100_001).unwrap(); let d2 = s.infer_dense(&[0.1, 3.0], 400_001).unwrap();
    println!("dense 1e5 vs 4e5: {}", (d1-d2).abs());
    println!("u(0,0)={} u(0.3,0)={}", s.infer(&[0.0,0.0]).unwrap(), s.infer(&[0.3,0.0]).unwrap());
}
