//! Exact form factors for polygon pairs read from stdin, with a per-pair time.
//!
//! Input: JSON lines `{"name": "...", "p1": [[x,y,z],...], "p2": [[x,y,z],...]}`, each
//! polygon planar, convex and counter-clockwise seen from its front.
//! Output: JSON lines `{"name": ..., "f": F_12, "seconds_per_pair": ...}`.
//!
//! Each pair is computed repeatedly (at least 20 ms of work and at least 10 calls, after
//! one untimed call) and the mean time per call reported. Used by
//! `bench/pyviewfactor_compare.py`; not part of the test suite.
//!
//! ```sh
//! echo '{"name":"squares","p1":[[0,0,0],[1,0,0],[1,1,0],[0,1,0]],"p2":[[0,0,1],[0,1,1],[1,1,1],[1,0,1]]}' \
//!   | cargo run --release -p radiosity --example viewfactor_pairs
//! ```

use std::hint::black_box;
use std::io::{self, BufRead, Write};
use std::time::{Duration, Instant};

use glam::DVec3;
use radiosity::form_factor::exact::polygon_to_polygon;
use serde::{Deserialize, Serialize};

#[derive(Deserialize)]
struct Pair {
    name: String,
    p1: Vec<[f64; 3]>,
    p2: Vec<[f64; 3]>,
}

#[derive(Serialize)]
struct Record<'a> {
    name: &'a str,
    f: f64,
    seconds_per_pair: f64,
}

const MIN_TIME: Duration = Duration::from_millis(20);
const MIN_CALLS: u64 = 10;

fn to_points(poly: &[[f64; 3]]) -> Vec<DVec3> {
    poly.iter().map(|&p| DVec3::from_array(p)).collect()
}

/// Mean seconds per call of `polygon_to_polygon(p1, p2)` over batches doubled until the
/// whole run takes at least `MIN_TIME`.
fn time_pair(p1: &[DVec3], p2: &[DVec3]) -> f64 {
    black_box(polygon_to_polygon(black_box(p1), black_box(p2)));
    let mut calls = MIN_CALLS;
    loop {
        let start = Instant::now();
        for _ in 0..calls {
            black_box(polygon_to_polygon(black_box(p1), black_box(p2)));
        }
        let elapsed = start.elapsed();
        if elapsed >= MIN_TIME {
            return elapsed.as_secs_f64() / calls as f64;
        }
        calls *= 2;
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let stdin = io::stdin();
    let mut out = io::stdout().lock();
    for (n, line) in stdin.lock().lines().enumerate() {
        let line = line?;
        if line.trim().is_empty() {
            continue;
        }
        let pair: Pair = serde_json::from_str(&line).map_err(|e| format!("line {}: {e}", n + 1))?;
        let (p1, p2) = (to_points(&pair.p1), to_points(&pair.p2));
        if p1.len() < 3 || p2.len() < 3 {
            return Err(format!("line {}: a polygon needs at least 3 vertices", n + 1).into());
        }
        let f = polygon_to_polygon(&p1, &p2);
        let seconds = time_pair(&p1, &p2);
        let record = Record {
            name: &pair.name,
            f,
            seconds_per_pair: seconds,
        };
        writeln!(out, "{}", serde_json::to_string(&record)?)?;
        out.flush()?;
    }
    Ok(())
}
