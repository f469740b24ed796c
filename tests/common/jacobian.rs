//! The assembled Jacobian of a scene held against its Jacobian–vector products and central
//! differences of the right-hand side.

use geartherm::scene::{Scene, Work};

/// The dense Jacobian (column-major, n × n) assembled from the scene's sparse values at `y`,
/// after asserting each column against central differences of the right-hand side (relative
/// 1e-6 of the column's largest entry) and against the Jacobian–vector products (relative
/// 1e-12).
pub fn checked_dense_jacobian(scene: &Scene, y: &[f64], work: &mut Work) -> Vec<f64> {
    let pattern = scene.jacobian_pattern();
    let mut vals = vec![0.0; pattern.len()];
    scene.jacobian_values(0.0, y, work, &mut vals);
    let n = scene.n_states();
    let mut dense = vec![0.0; n * n];
    for (&(r, c), v) in pattern.iter().zip(&vals) {
        dense[r + c * n] += v;
    }
    let (mut v, mut col, mut fp, mut fm) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut worst: f64 = 0.0;
    for j in 0..n {
        v.iter_mut().for_each(|x| *x = 0.0);
        v[j] = 1.0;
        scene.jvp(0.0, y, &v, work, &mut col);
        let h = 1e-6 * y[j].abs().max(1.0);
        let (mut yp, mut ym) = (y.to_vec(), y.to_vec());
        yp[j] += h;
        ym[j] -= h;
        scene.rhs(0.0, &yp, work, &mut fp);
        scene.rhs(0.0, &ym, work, &mut fm);
        let scale = (0..n)
            .map(|i| dense[i + j * n].abs().max(col[i].abs()))
            .fold(1e-12, f64::max);
        for i in 0..n {
            let fd = (fp[i] - fm[i]) / (2.0 * h);
            worst = worst.max((dense[i + j * n] - col[i]).abs() / scale);
            assert!(
                (dense[i + j * n] - fd).abs() <= 1e-6 * scale,
                "J[{i},{j}] = {} vs difference {fd}",
                dense[i + j * n]
            );
        }
    }
    assert!(worst < 1e-12, "assembled vs products {worst}");
    dense
}
