//! Picks the BVH / ray-query crate for radiosity by measurement: occlusion (any-hit, finite
//! segment) and closest-hit queries per second on a fixed thread count, build time, and
//! agreement between the crates on every query. See README.md.

mod engines;
mod scene;

use std::time::Instant;

use rayon::prelude::*;
use scene::Query;

struct Args {
    scenes: Vec<String>,
    tris: usize,
    queries: usize,
    reps: usize,
    threads: usize,
    only: Option<Vec<String>>,
}

fn args() -> Args {
    let mut a = Args {
        scenes: vec!["building".into(), "soup".into()],
        tris: 100_000,
        queries: 1_000_000,
        reps: 3,
        threads: 2,
        only: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(k) = it.next() {
        let mut v = || it.next().unwrap_or_else(|| panic!("{k} needs a value"));
        match k.as_str() {
            "--scene" => a.scenes = v().split(',').map(String::from).collect(),
            "--tris" => a.tris = v().parse().unwrap(),
            "--queries" => a.queries = v().parse().unwrap(),
            "--reps" => a.reps = v().parse().unwrap(),
            "--threads" => a.threads = v().parse().unwrap(),
            "--only" => a.only = Some(v().split(',').map(String::from).collect()),
            "-h" | "--help" => {
                println!("bvh-compare [--scene building,soup] [--tris 100000] [--queries 1000000] [--reps 3] [--threads 2] [--only obvhs,obvhs-wt,bvh,parry3d,embree3]");
                std::process::exit(0);
            }
            _ => panic!("unknown argument {k}"),
        }
    }
    a
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

struct Record {
    name: &'static str,
    version: &'static str,
    build_ms: Vec<f64>,
    any: Vec<f64>,
    closest: Vec<f64>,
    any_result: Vec<bool>,
    closest_result: Vec<Option<(u32, f32)>>,
}

fn main() {
    let a = args();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads)
        .build()
        .unwrap();
    println!(
        "bvh-compare: {} triangles, {} queries of each kind, {} rayon threads, {} repetitions (medians reported)",
        a.tris, a.queries, a.threads, a.reps
    );
    let mut makers = engines::all(a.threads);
    if let Some(only) = &a.only {
        makers.retain(|m| only.iter().any(|o| o == m.name));
    }
    for scene_name in &a.scenes {
        let t = Instant::now();
        let tris = match scene_name.as_str() {
            "building" => scene::building(a.tris, 1),
            "soup" => scene::soup(a.tris, 2),
            s => panic!("unknown scene {s}"),
        };
        let diag = scene::diagonal(&tris);
        // Segment ends are trimmed by 1e-5 of the scene diagonal (f32 leaves no room for
        // the 1e-7 the library uses in f64).
        let eps = 1e-5 * diag;
        let segs = scene::segments(&tris, a.queries, eps, 3);
        let rays = scene::rays(&tris, a.queries, eps, 4);
        println!(
            "\n## scene {scene_name}: {} triangles, diagonal {diag:.2}, generated in {:.0} ms",
            tris.len(),
            t.elapsed().as_secs_f64() * 1e3
        );

        let mut records: Vec<Record> = makers
            .iter()
            .map(|m| Record {
                name: m.name,
                version: m.version,
                build_ms: vec![],
                any: vec![],
                closest: vec![],
                any_result: vec![],
                closest_result: vec![],
            })
            .collect();
        for rep in 0..a.reps {
            // Rotate the order each repetition so no crate always runs first or last.
            for j in 0..makers.len() {
                let i = (j + rep) % makers.len();
                let m = &makers[i];
                let t = Instant::now();
                let e = pool.install(|| (m.build)(&tris));
                let build = t.elapsed().as_secs_f64() * 1e3;
                let (any, any_s) = timed(&pool, &segs, |q| e.occluded(q));
                let (closest, closest_s) = timed(&pool, &rays, |q| e.closest(q));
                let r = &mut records[i];
                r.build_ms.push(build);
                r.any.push(segs.len() as f64 / any_s / 1e6);
                r.closest.push(rays.len() as f64 / closest_s / 1e6);
                let hits = any.iter().filter(|&&h| h).count();
                println!(
                    "  rep {rep} {:<9} build {build:8.1} ms  any-hit {:6.3} Mrays/s ({hits} blocked)  closest-hit {:6.3} Mrays/s",
                    m.name,
                    r.any.last().unwrap(),
                    r.closest.last().unwrap()
                );
                if rep == 0 {
                    r.any_result = any;
                    r.closest_result = closest;
                }
            }
        }
        report(&records, &tris, &segs, &rays, diag);
    }
}

fn timed<T: Send>(
    pool: &rayon::ThreadPool,
    qs: &[Query],
    f: impl Fn(&Query) -> T + Sync,
) -> (Vec<T>, f64) {
    let t = Instant::now();
    let r = pool.install(|| qs.par_iter().with_min_len(256).map(&f).collect::<Vec<T>>());
    (r, t.elapsed().as_secs_f64())
}

fn report(records: &[Record], tris: &[scene::Tri], segs: &[Query], rays: &[Query], diag: f64) {
    // Reference for agreement: embree3 when present, else the first crate.
    let refi = records.iter().position(|r| r.name == "embree3").unwrap_or(0);
    let base = records.iter().position(|r| r.name == "obvhs").unwrap_or(0);
    let reference = &records[refi];
    // Any-hit mismatches, judged by an f64 brute-force test over all triangles (up to 200
    // of them per crate).
    println!(
        "\n| crate | version | build ms | any-hit Mrays/s | closest-hit Mrays/s | any-hit vs {b} | closest-hit vs {b} | any-hit mismatches vs {r} (f64 brute force sides with this crate) | closest-hit mismatches vs {r}: hit/miss, other t |",
        b = records[base].name,
        r = reference.name
    );
    println!("| --- | --- | ---: | ---: | ---: | ---: | ---: | --- | --- |");
    for r in records {
        let ratio = |x: &Vec<f64>, y: &Vec<f64>| {
            median(&x.iter().zip(y).map(|(a, b)| a / b).collect::<Vec<_>>())
        };
        let any_ratio = ratio(&r.any, &records[base].any);
        let closest_ratio = ratio(&r.closest, &records[base].closest);
        let mism: Vec<usize> = (0..segs.len())
            .filter(|&i| r.any_result[i] != reference.any_result[i])
            .collect();
        let judged = mism.len().min(200);
        let sides = mism[..judged]
            .iter()
            .filter(|&&i| engines::brute_f64(tris, &segs[i]) == r.any_result[i])
            .count();
        let (mut hm, mut tdiff) = (0, 0);
        for i in 0..rays.len() {
            match (r.closest_result[i], reference.closest_result[i]) {
                (Some((ia, ta)), Some((ib, tb))) => {
                    if ia != ib && (ta - tb).abs() as f64 > 1e-5 * diag {
                        tdiff += 1
                    }
                }
                (None, None) => {}
                _ => hm += 1,
            }
        }
        let any_m = if r.name == reference.name {
            "reference".to_string()
        } else {
            format!("{} ({sides} of {judged})", mism.len())
        };
        let cl_m = if r.name == reference.name {
            "reference".to_string()
        } else {
            format!("{hm}, {tdiff}")
        };
        println!(
            "| {} | {} | {:.0} | {:.3} | {:.3} | {:.2}x | {:.2}x | {} | {} |",
            r.name,
            r.version,
            median(&r.build_ms),
            median(&r.any),
            median(&r.closest),
            any_ratio,
            closest_ratio,
            any_m,
            cl_m
        );
    }
    let blocked = reference.any_result.iter().filter(|&&h| h).count();
    let hit = reference.closest_result.iter().filter(|h| h.is_some()).count();
    println!(
        "({blocked} of {} segments blocked, {hit} of {} rays hit, per {})",
        segs.len(),
        rays.len(),
        reference.name
    );
}
