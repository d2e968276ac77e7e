//! Criterion benchmarks of the pipeline's costly stages on the built-in Cornell box:
//! form factors at about 500 elements, the LU and Gauss-Seidel solves of the same matrix
//! (one group, so the two are compared as a ratio measured in one run), and rendering a
//! 256 x 256 image. Sample counts are small so that `cargo bench` ends in a few minutes on
//! two cores. Figures: BENCHMARKS.md.

use std::hint::black_box;
use std::time::Duration;

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion};
use radiosity::pipeline::Prepared;
use radiosity::pipeline::{self as run, FormFactors, SolveRequest};
use radiosity::progress::NoProgress;
use radiosity::render::{self, Camera, RenderSettings, Renderer};
use radiosity::scene::{cornell_box, MeshSettings};
use radiosity::shade::{self, Exposure};
use radiosity::solve::{self, keep_going, DenseSolver, GaussSeidelSettings, Solver};

/// MAX_PATCH_AREA (mm^2) that cuts the Cornell box into about 500 elements (535 with the red wall as two triangles).
const MAX_AREA: f64 = 4000.0;

fn prepared() -> Prepared {
    let settings = MeshSettings {
        max_patch_area: MAX_AREA,
        integral_steps: 2,
    };
    Prepared::new(cornell_box().scene, settings, &NoProgress).expect("the Cornell box meshes")
}

fn configure<'c>(c: &'c mut Criterion, name: &str) -> BenchmarkGroup<'c, WallTime> {
    let mut group = c.benchmark_group(name);
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5));
    group
}

fn form_factors(c: &mut Criterion) {
    let p = prepared();
    let mut group = configure(c, "form_factors");
    let id = format!("cornell_{}_elements_k2", p.mesh.len());
    group.bench_function(id, |b| {
        b.iter(|| black_box(p.form_factors(&NoProgress).expect("fits in memory")))
    });
    group.finish();
}

fn solvers(c: &mut Criterion) {
    let p = prepared();
    let (f, _) = p.form_factors(&NoProgress).expect("fits in memory");
    let mut group = configure(c, "solve");
    let n = p.mesh.len();
    let gauss_seidel = DenseSolver::GaussSeidel(GaussSeidelSettings::default());
    for (name, solver) in [("lu", DenseSolver::Lu), ("gauss_seidel", gauss_seidel)] {
        group.bench_function(format!("{name}_{n}_elements"), |b| {
            b.iter(|| {
                black_box(
                    solve::solve(&f, &p.light, &solver, None, &mut keep_going, &NoProgress)
                        .unwrap(),
                )
            })
        });
    }
    group.finish();
}

fn rendering(c: &mut Criterion) {
    let p = prepared();
    let (f, _) = p.form_factors(&NoProgress).expect("fits in memory");
    let request = SolveRequest {
        form_factors: FormFactors::Matrix(&f),
        ..SolveRequest::new(Solver::LU)
    };
    let solution = run::solve(&p, &request, &mut keep_going, &NoProgress).unwrap();
    let element_b = solution.element_rgb();
    let vertex_b = shade::vertex_radiosity(&p.mesh, element_b);
    let settings = RenderSettings {
        exposure_scale: Exposure::Auto.scale(&p.scene, &p.mesh, element_b),
        ..RenderSettings::default()
    };
    let camera = Camera::for_scene(&p.scene, 256, 256);
    let renderer = Renderer::new(&p.mesh);
    let mut group = configure(c, "render");
    group.bench_function("cornell_256x256_smooth", |b| {
        b.iter(|| {
            black_box(render::render(
                &renderer,
                &camera,
                element_b,
                &vertex_b,
                &settings,
                &NoProgress,
            ))
        })
    });
    group.finish();
}

criterion_group!(benches, form_factors, solvers, rendering);
criterion_main!(benches);
