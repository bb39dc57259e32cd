//! Fits the table of the sheen lobe (crates/tracer/src/bsdf/sheen.rs) as Zeltner, Burley &
//! Chiang 2022 ("Practical Multiple-Scattering Sheen Using Linearly Transformed Cosines")
//! describe it: the reference is a volumetric layer of fibres standing along the normal, and per
//! table cell (the cosine μ of the viewing direction × the roughness α, 32 × 32, grid points
//! i/31 with 0 raised to 0.01) the linearly transformed cosine with inverse matrix
//! [[a, 0, b], [0, a, 0], [0, 0, 1]] is fitted to the light the layer reflects, and the
//! layer's directional albedo R is kept beside it.
//!
//! The layer: unit thickness, density 1, white (single-scattering albedo 1), over nothing (light
//! leaving through the bottom is lost), filled with specular microflakes of the SGGX
//! distribution of a fibre along z, S = diag(1, 1, σ²) with σ = α² (the paper's mapping). A
//! path enters at the top against the viewing direction, flies exponential distances with the
//! direction-dependent extinction σ(ω) = √(ωᵀSω), reflects off a visible microflake normal at
//! each event and is counted where it leaves through the top; as in the paper's simulation the
//! walk stops after 16 events, counted as reflected if it then heads up.
//!
//! The fit: the paper minimises an L3 distance on a histogram of the reflected directions; this
//! tool maximises the likelihood of the reflected directions themselves under the LTC (the
//! Kullback–Leibler projection of the simulated lobe onto the LTC family), by Nelder–Mead from
//! the solution of the next rougher cell, as the paper sweeps. R is the fraction of paths
//! reflected. Each cell draws its own deterministic random sequence, so the output is the same
//! bits for any number of threads.
//!
//! Usage: `sheen-fit OUT.rs [PATHS_PER_CELL]` (default 262144).

use std::fmt::Write as _;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

const N: usize = 32;
const MAX_EVENTS: usize = 16;
/// Reflected directions the likelihood is computed over, at most.
const FIT_SAMPLES: usize = 1 << 16;

/// A permuted congruential generator (PCG32, O'Neill 2014): small, fast and reproducible.
struct Pcg(u64);

impl Pcg {
    fn new(seed: u64) -> Self {
        let mut p = Pcg(0);
        p.next();
        p.0 = p.0.wrapping_add(seed);
        p.next();
        p
    }
    fn next(&mut self) -> u32 {
        let old = self.0;
        self.0 = old.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }
    /// Uniform in [0, 1).
    fn f(&mut self) -> f64 {
        let hi = (self.next() as u64) << 21;
        let lo = (self.next() >> 11) as u64;
        ((hi | lo) as f64) * (1.0 / (1u64 << 53) as f64)
    }
}

type V = [f64; 3];

fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn norm(a: V) -> V {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}
/// Two unit vectors completing `n` (unit) to an orthonormal basis (Duff et al. 2017).
fn basis(n: V) -> (V, V) {
    let sign = 1f64.copysign(n[2]);
    let a = -1.0 / (sign + n[2]);
    let b = n[0] * n[1] * a;
    ([1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]], [b, sign + n[1] * n[1] * a, -n[1]])
}

/// The fibre layer of SGGX cross-section σ (= α²).
struct Layer {
    s: f64,
}

impl Layer {
    /// The projected area σ(ω) = √(ωᵀSω) of the microflakes seen along unit ω: the extinction.
    fn extinction(&self, w: V) -> f64 {
        (w[0] * w[0] + w[1] * w[1] + self.s * self.s * w[2] * w[2]).sqrt()
    }

    /// A microflake normal seen from unit `v`, in proportion to max(0, v·m) D(m). The SGGX
    /// distribution of S is the normal distribution of the ellipsoid A·(unit ball), A =
    /// diag(σ, σ, 1) (a needle along z); a linear map keeps parallel rays parallel and their
    /// cross-section uniform, so a point uniform on the unit sphere's disk as seen along
    /// A⁻¹v maps to a point uniform on the ellipsoid's projection along v, whose normal is
    /// A⁻ᵀ p.
    fn visible_normal(&self, v: V, u1: f64, u2: f64) -> V {
        let s = self.s;
        let d = norm([v[0] / s, v[1] / s, v[2]]);
        let (t1, t2) = basis(d);
        let r = u1.sqrt();
        let phi = 2.0 * std::f64::consts::PI * u2;
        let (x, y) = (r * phi.cos(), r * phi.sin());
        let z = (1.0 - r * r).max(0.0).sqrt();
        let p = [
            x * t1[0] + y * t2[0] + z * d[0],
            x * t1[1] + y * t2[1] + z * d[1],
            x * t1[2] + y * t2[2] + z * d[2],
        ];
        norm([p[0] / s, p[1] / s, p[2]])
    }

    /// One random walk entering against the viewing direction `wo` (unit, z > 0); the direction
    /// it leaves the top by, if it does.
    fn walk(&self, wo: V, rng: &mut Pcg) -> Option<V> {
        let mut dir = [-wo[0], -wo[1], -wo[2]];
        // Depth below the top: 0 at the top, 1 at the bottom.
        let mut depth = 0.0;
        for _ in 0..MAX_EVENTS {
            let t = -(1.0 - rng.f()).ln() / self.extinction(dir);
            depth -= t * dir[2];
            if depth < 0.0 {
                return Some(dir);
            }
            if depth > 1.0 {
                return None;
            }
            let v = [-dir[0], -dir[1], -dir[2]];
            let m = self.visible_normal(v, rng.f(), rng.f());
            let c = 2.0 * dot(m, v);
            dir = norm([c * m[0] - v[0], c * m[1] - v[1], c * m[2] - v[2]]);
        }
        (dir[2] > 0.0).then_some(dir)
    }
}

/// The mean negative log-likelihood (without constants) of unit directions `w` under the LTC
/// of inverse matrix [[a, 0, b], [0, a, 0], [0, 0, 1]]: D(ω) = z a² / (π ‖M⁻¹ω‖⁴).
fn nll(x: [f64; 2], w: &[V]) -> f64 {
    let (a, b) = (x[0], x[1]);
    if a <= 1e-4 {
        return f64::INFINITY;
    }
    let sum: f64 = w
        .iter()
        .map(|w| {
            let l = (a * w[0] + b * w[2]).powi(2) + (a * w[1]).powi(2) + w[2] * w[2];
            2.0 * l.ln()
        })
        .sum();
    sum / w.len() as f64 - 2.0 * a.ln()
}

/// Nelder–Mead (reflection 1, expansion 2, contraction ½, shrink ½) from `x0`.
fn minimise(f: impl Fn([f64; 2]) -> f64, x0: [f64; 2]) -> [f64; 2] {
    let mut s = [x0, [x0[0] + 0.1, x0[1]], [x0[0], x0[1] + 0.05]];
    let mut fs = s.map(&f);
    for _ in 0..2000 {
        let mut idx = [0, 1, 2];
        idx.sort_by(|&i, &j| fs[i].total_cmp(&fs[j]));
        s = idx.map(|i| s[i]);
        fs = idx.map(|i| fs[i]);
        if (fs[2] - fs[0]).abs() < 1e-12 && (s[2][0] - s[0][0]).abs() + (s[2][1] - s[0][1]).abs() < 1e-7 {
            break;
        }
        let c = [(s[0][0] + s[1][0]) / 2.0, (s[0][1] + s[1][1]) / 2.0];
        let at = |t: f64| [c[0] + t * (s[2][0] - c[0]), c[1] + t * (s[2][1] - c[1])];
        let xr = at(-1.0);
        let fr = f(xr);
        if fr < fs[0] {
            let xe = at(-2.0);
            let fe = f(xe);
            (s[2], fs[2]) = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < fs[1] {
            (s[2], fs[2]) = (xr, fr);
        } else {
            let xc = if fr < fs[2] { at(-0.5) } else { at(0.5) };
            let fc = f(xc);
            if fc < fs[2].min(fr) {
                (s[2], fs[2]) = (xc, fc);
            } else {
                for i in 1..3 {
                    s[i] = [(s[0][0] + s[i][0]) / 2.0, (s[0][1] + s[i][1]) / 2.0];
                    fs[i] = f(s[i]);
                }
            }
        }
    }
    let best = (0..3).min_by(|&i, &j| fs[i].total_cmp(&fs[j])).unwrap();
    s[best]
}

/// The grid value of index `i`: i/31, with 0 raised to 0.01 (the paper's grid).
fn grid(i: usize) -> f64 {
    (i as f64 / (N - 1) as f64).max(0.01)
}

/// One table column: for μ index `mi`, every roughness from the roughest down (each fit starts
/// from the previous one), as (a, b, R).
fn column(mi: usize, paths: usize) -> [[f64; 3]; N] {
    let mu = grid(mi);
    let wo = [(1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu];
    let mut out = [[0.0; 3]; N];
    let mut x = [1.0, 0.0];
    for ai in (0..N).rev() {
        let alpha = grid(ai);
        let layer = Layer { s: alpha * alpha };
        let mut rng = Pcg::new((mi * N + ai) as u64 * 0x9E37_79B9_7F4A_7C15 + 1);
        let mut reflected = 0usize;
        let mut fit = Vec::with_capacity(FIT_SAMPLES);
        for _ in 0..paths {
            if let Some(w) = layer.walk(wo, &mut rng) {
                reflected += 1;
                if fit.len() < FIT_SAMPLES {
                    fit.push(w);
                }
            }
        }
        // Too few reflected paths to shape a lobe (the albedo is then negligible): keep the
        // rougher neighbour's shape.
        if fit.len() >= 256 {
            x = minimise(|x| nll(x, &fit), x);
        }
        out[ai] = [x[0], x[1], reflected as f64 / paths as f64];
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(out_path) = args.get(1) else {
        eprintln!("usage: sheen-fit OUT.rs [PATHS_PER_CELL]");
        std::process::exit(2);
    };
    let paths: usize = match args.get(2).map(|s| s.parse()) {
        None => 1 << 18,
        Some(Ok(n)) if n > 0 => n,
        Some(_) => {
            eprintln!("sheen-fit: PATHS_PER_CELL must be a positive integer, not {:?}", args[2]);
            std::process::exit(2);
        }
    };
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let next = AtomicUsize::new(0);
    let table = Mutex::new([[[0.0f64; 3]; N]; N]);
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                loop {
                    let mi = next.fetch_add(1, Ordering::Relaxed);
                    if mi >= N {
                        break;
                    }
                    let col = column(mi, paths);
                    let mut t = table.lock().unwrap();
                    for ai in 0..N {
                        t[ai][mi] = col[ai];
                    }
                    eprintln!("sheen-fit: μ column {mi} done");
                }
            });
        }
    });
    let table = table.into_inner().unwrap();
    let mut s = String::new();
    s.push_str("//! The sheen lobe's table (`sheen.rs`), generated by tools/sheen-fit: do not edit. Regenerate\n");
    let _ = writeln!(
        s,
        "//! with `cargo run --release --manifest-path tools/sheen-fit/Cargo.toml -- {out_path} {paths}`."
    );
    s.push_str("//! Indexed [roughness][μ], grid points i/31: the LTC's inverse-matrix entries a and b, and\n");
    s.push_str("//! the directional albedo R of the simulated fibre layer.\n\n");
    for (k, (name, doc)) in [
        ("A", "The diagonal entries a of the LTC's inverse matrix."),
        ("B", "The entry b (row 1, column 3) of the LTC's inverse matrix."),
        ("R", "The fibre layer's directional albedo."),
    ]
    .iter()
    .enumerate()
    {
        let _ = writeln!(s, "/// {doc}");
        let _ = writeln!(s, "#[rustfmt::skip]\npub(super) const {name}: [[f32; {N}]; {N}] = [");
        for row in &table {
            s.push_str("    [");
            for (i, cell) in row.iter().enumerate() {
                if i > 0 {
                    s.push_str(", ");
                }
                let _ = write!(s, "{:.6}", cell[k] as f32);
            }
            s.push_str("],\n");
        }
        s.push_str("];\n\n");
    }
    let s = s.trim_end().to_string() + "\n";
    let tmp = format!("{out_path}.tmp");
    if let Err(e) = std::fs::write(&tmp, s).and_then(|()| std::fs::rename(&tmp, out_path)) {
        eprintln!("sheen-fit: cannot write {out_path}: {e}");
        std::process::exit(1);
    }
}
