//! Per-camera planes (one value per pixel per camera, row-major), as the blend steps pass them
//! between each other. A leaf the steps share.

/// Splits per-camera planes into rows: `rows[y][k]` is row y of plane k (for row-parallel passes
/// that touch every camera at a pixel).
pub(crate) fn rows_mut(planes: &mut [Vec<f32>], width: usize) -> Vec<Vec<&mut [f32]>> {
    let height = planes.first().map_or(0, |p| p.len() / width.max(1));
    let mut rows: Vec<Vec<&mut [f32]>> = (0..height).map(|_| Vec::with_capacity(planes.len())).collect();
    for plane in planes.iter_mut() {
        for (row, chunk) in rows.iter_mut().zip(plane.chunks_exact_mut(width)) {
            row.push(chunk);
        }
    }
    rows
}
