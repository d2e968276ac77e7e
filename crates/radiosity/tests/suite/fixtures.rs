//! Scenes and helpers that several of the suite's modules share: grey surfaces, the closed
//! unit cube, a scene's mesh with its occluders and form-factor matrix, and the Cornell box
//! prepared and solved densely.

use glam::{dvec3, DVec3};
use radiosity::form_factor::{
    compute_matrix, occluder_bvh, FormFactorContext, FormFactorMatrix, FormFactorMethod, RayCounter,
};
use radiosity::mesh::{mesh_scene, Mesh};
use radiosity::pipeline::{self, Overrides, Prepared, Solution, SolveRequest};
use radiosity::progress::NoProgress;
use radiosity::scene::{cornell_box, Rgb, Scene, SceneFile, Surface};
use radiosity::solve::{keep_going, Solver};
use radiosity::visibility::PolygonBvh;

/// A surface that emits nothing and reflects half of every band.
pub fn surface(name: &str, vertices: Vec<DVec3>) -> Surface {
    Surface {
        name: name.into(),
        emission: Rgb::BLACK,
        reflectance: Rgb([0.5; 3]),
        vertices,
        photometry: Default::default(),
    }
}

/// The closed unit cube [0, 1]^3, every face looking in, grey and dark (see [`surface`]):
/// faces `face0` to `face5` at z = 0, z = 1, x = 0, x = 1, y = 0 and y = 1. It is the scene
/// of the closed-box and reciprocity columns of the library's accuracy table
/// (`form_factor::accuracy`), vertex for vertex (`closed_cube_is_the_accuracy_tables_closed_box`
/// checks it).
pub fn closed_cube() -> Scene {
    let c = |x: f64, y: f64, z: f64| dvec3(x, y, z);
    // Each face counter-clockwise seen from inside the cube.
    let faces = [
        [c(1., 0., 0.), c(1., 1., 0.), c(0., 1., 0.), c(0., 0., 0.)],
        [c(0., 1., 1.), c(1., 1., 1.), c(1., 0., 1.), c(0., 0., 1.)],
        [c(0., 1., 0.), c(0., 1., 1.), c(0., 0., 1.), c(0., 0., 0.)],
        [c(1., 0., 1.), c(1., 1., 1.), c(1., 1., 0.), c(1., 0., 0.)],
        [c(0., 0., 1.), c(1., 0., 1.), c(1., 0., 0.), c(0., 0., 0.)],
        [c(1., 1., 0.), c(1., 1., 1.), c(0., 1., 1.), c(0., 1., 0.)],
    ];
    Scene {
        surfaces: faces
            .into_iter()
            .enumerate()
            .map(|(i, v)| surface(&format!("face{i}"), v.to_vec()))
            .collect(),
        camera: None,
        lights: Vec::new(),
    }
}

/// The [`closed_cube`] with face `i` emitting `emission(i)` and every face reflecting
/// `reflectance`.
pub fn lit_closed_cube(emission: impl Fn(usize) -> [f64; 3], reflectance: [f64; 3]) -> Scene {
    let mut scene = closed_cube();
    for (i, s) in scene.surfaces.iter_mut().enumerate() {
        s.emission = Rgb(emission(i));
        s.reflectance = Rgb(reflectance);
    }
    scene
}

/// A scene's mesh and its occluders: what the form-factor methods take.
pub struct Meshed {
    pub mesh: Mesh,
    pub occluders: PolygonBvh,
}

impl Meshed {
    /// `scene` meshed into elements of at most `max_area`.
    pub fn new(scene: &Scene, max_area: f64) -> Meshed {
        Meshed {
            mesh: mesh_scene(scene, max_area).unwrap(),
            occluders: occluder_bvh(scene),
        }
    }

    pub fn ctx(&self) -> FormFactorContext<'_> {
        FormFactorContext {
            mesh: &self.mesh,
            occluders: &self.occluders,
        }
    }

    /// The full form-factor matrix by `method`.
    pub fn matrix(&self, method: FormFactorMethod) -> FormFactorMatrix {
        compute_matrix(&self.ctx(), method, &RayCounter::default(), &NoProgress).unwrap()
    }
}

/// `scene` meshed into elements of at most `max_area`, and its form-factor matrix by
/// `method`.
pub fn matrix_for(
    scene: &Scene,
    max_area: f64,
    method: FormFactorMethod,
) -> (FormFactorMatrix, Mesh) {
    let meshed = Meshed::new(scene, max_area);
    (meshed.matrix(method), meshed.mesh)
}

/// The area of every element of `mesh`, in element order.
pub fn element_areas(mesh: &Mesh) -> Vec<f64> {
    mesh.elements.iter().map(|e| e.area).collect()
}

/// The built-in Cornell box prepared at MAX_PATCH_AREA `max_area` (mm^2) and, where given,
/// INTEGRAL_STEPS `steps` (else the scene file's own).
pub fn prepared_cornell(max_area: f64, steps: Option<u32>) -> Prepared {
    let file = cornell_box();
    let overrides = Overrides {
        max_patch_area: Some(max_area),
        integral_steps: steps,
    };
    Prepared::new(file.scene, overrides.apply(file.settings), &NoProgress).unwrap()
}

/// `prepared` solved by dense Gauss-Seidel at the library's default settings.
pub fn dense_gauss_seidel(prepared: &Prepared) -> Solution {
    pipeline::solve(
        prepared,
        &SolveRequest::new(Solver::DEFAULT_GAUSS_SEIDEL),
        &mut keep_going,
        &NoProgress,
    )
    .unwrap()
}

/// The scene of `contact.scene`: a floor with a rug lying in its plane, a block standing on
/// the floor against the back wall, a stool standing on the rug and a light panel above
/// (surfaces that lie on or touch others, their faces coplanar), MAX_PATCH_AREA 0.1 m^2.
pub fn contact_scene() -> SceneFile {
    radiosity::io::scene_file::parse_scene(include_str!("contact.scene"), "contact.scene").unwrap()
}

// ----- the fixtures' own checks -----

#[test]
fn closed_cube_faces_are_unit_squares_looking_in() {
    let scene = closed_cube();
    assert_eq!(scene.surfaces.len(), 6);
    let centre = dvec3(0.5, 0.5, 0.5);
    for s in &scene.surfaces {
        assert_eq!(
            radiosity::geometry::polygon_area(&s.vertices),
            1.0,
            "{}",
            s.name
        );
        let n = radiosity::geometry::polygon_normal(&s.vertices).unwrap();
        let towards_centre = centre - radiosity::geometry::polygon_centroid(&s.vertices);
        // The unit normal points straight at the centre, half a unit away.
        assert!(
            (n - 2.0 * towards_centre).length() < 1e-15,
            "{}: normal {n}",
            s.name
        );
    }
    // Elements per face: 1, 2 x 2, 3 x 3.
    for (max_area, elements) in [(1.0, 6), (0.25, 24), (1.0 / 9.0, 54)] {
        assert_eq!(mesh_scene(&scene, max_area).unwrap().len(), elements);
    }
}

// The accuracy table measures the closed-box row sums and the reciprocity on its own
// closed cube; Monte Carlo's values depend on every element's corners and their order, so
// equal values mean the same mesh.
#[test]
fn closed_cube_is_the_accuracy_tables_closed_box() {
    let method = FormFactorMethod::MonteCarlo {
        samples: 256,
        seed: 1,
    };
    let max_area = 1.0 / 9.0;
    let row = radiosity::form_factor::accuracy::measure(method, max_area);
    let (f, mesh) = matrix_for(&closed_cube(), max_area, method);
    assert_eq!(mesh.len(), 54);
    let closed_box = (0..f.n())
        .map(|i| (f.row_sum(i) - 1.0).abs())
        .fold(0.0, f64::max);
    let reciprocity = f.reciprocity(&element_areas(&mesh)).total_relative;
    assert!(reciprocity > 0.0, "Monte Carlo is not reciprocal");
    assert_eq!(closed_box, row.closed_box);
    assert_eq!(reciprocity, row.reciprocity);
}
