//! The command line's flags, first stage: what clap parses, as typed as clap can make it
//! (the value parsers at the end turn "x,y,z", "auto" and the like into the library's
//! types, so that a bad value is refused, with its flag named, before any work).
//! The second stage, [`crate::setup`], turns them into the library's objects (a
//! [`radiosity::pipeline::Prepared`] scene, a [`radiosity::solve::Solver`], a camera...)
//! and checks what depends on more than one flag.

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};
use glam::DVec3;
use radiosity::render::Shading;
use radiosity::shade::Exposure;
use radiosity::solve::SolverKind;

/// `cmd` with every flag that takes a value, in it and its subcommands, accepting a
/// negative number (`--tolerance -1`, `--scale -2`): clap otherwise reads "-1" as an
/// unknown flag and suggests `-- -1`, which makes it a scene file name (QA of issue #16).
/// The value is then refused, if it must be positive, by a message naming the flag and what
/// it takes. The vectors (`--eye -1,2,3`) take any value starting with a hyphen
/// (`allow_hyphen_values`). `radiosity` and `radiosity-mpi` both parse through it.
pub fn negative_numbers(cmd: clap::Command) -> clap::Command {
    cmd.mut_args(|arg| {
        if !arg.is_positional() && arg.get_action().takes_values() {
            arg.allow_negative_numbers(true)
        } else {
            arg
        }
    })
    .mut_subcommands(negative_numbers)
}

#[derive(Subcommand)]
pub enum GenerateCommand {
    /// A building: a grid of furnished rooms on one or more floors, joined by doors, lit by
    /// a ceiling panel per room and daylight in every exterior window (metres).
    Building(BuildingArgs),
}

#[derive(Subcommand)]
pub enum ValidateCommand {
    /// The analytical cases of CIE 171:2006 for a diffuse program (5.2 point source, 5.3
    /// area source, 5.6 and 5.7 diffuse reflection without and with an obstruction, 5.8
    /// inter-reflection in a 4 m cube for reflectances 0 to 0.95, 5.9 and 5.11 openings under
    /// a uniform sky): runs each scene, prints case, point, reference, computed and
    /// difference in %, and fails if any is outside its target (1 % of the reference per
    /// point; 0.5 % for the cube's mean indirect illuminance).
    Cie171(Cie171Args),
}

#[derive(Args)]
pub struct Cie171Args {
    /// Write each case's scene and points file (name,x,y,z,nx,ny,nz) into DIR and stop
    /// (the repository keeps them under validation/); with --case, those cases' only.
    #[arg(long, value_name = "DIR")]
    pub write: Option<PathBuf>,
    /// With --write: replace the case files that are already in DIR (scene files are
    /// inputs: without this flag none is written over).
    #[arg(long, requires = "write")]
    pub force: bool,
    /// Run (or, with --write, write) only the cases whose id starts with this, e.g. 5.8 or
    /// 5.11.
    #[arg(long, value_name = "ID")]
    pub case: Option<String>,
    /// Only the verdict line (no table, no list of sources); the exit status still says
    /// whether every value is within its target.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Args)]
pub struct BuildingArgs {
    /// Output scene file, named *.scene; an existing file is not replaced without --force.
    #[arg(short, long, value_name = "FILE.scene")]
    pub output: PathBuf,
    /// Replace the output file if it exists (a scene file is an input of every other
    /// command: without this flag it is never written over).
    #[arg(long)]
    pub force: bool,
    /// Storeys.
    #[arg(long, default_value_t = 2, value_name = "N", value_parser = parse_at_least_1)]
    pub floors: u32,
    /// Rooms along x on each floor.
    #[arg(long, default_value_t = 6, value_name = "N", value_parser = parse_at_least_1)]
    pub rooms_x: u32,
    /// Rooms along z on each floor.
    #[arg(long, default_value_t = 6, value_name = "N", value_parser = parse_at_least_1)]
    pub rooms_z: u32,
    /// Inner side of each square room (m; 5.7 to 100 with furniture, from 2.5 without).
    #[arg(long, default_value_t = 6.0, value_name = "M")]
    pub room_size: f64,
    /// Floor-to-ceiling height (m; 2.4 to 20).
    #[arg(long, default_value_t = 2.7, value_name = "M")]
    pub height: f64,
    /// Empty rooms.
    #[arg(long)]
    pub no_furniture: bool,
    /// Seed of door positions, window widths, furniture placement and colours.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The scene's MAX_PATCH_AREA (m^2): 1 gives 92,946 elements for the default
    /// building (33,279 on the grid, split along furniture contacts and the faces just in front), 0.0125 about 990,000
    /// on the grid (the count is printed when the file is written).
    #[arg(long, default_value_t = 1.0, value_name = "AREA")]
    pub max_area: f64,
    /// The scene's INTEGRAL_STEPS.
    #[arg(long, default_value_t = 2, value_name = "K")]
    pub steps: u32,
    /// Exitance of the ceiling panels in the red band (lm/m^2, so that `illuminance` gives
    /// lux): they are tinted warm (1, 0.95, 0.85 times it), so their luminous exitance is
    /// 0.953 of it; windows emit 0.6 of it, bluish.
    #[arg(long, default_value_t = 20.0, value_name = "E")]
    pub light: f64,
    /// No summary line (rooms, surfaces, size and element count; errors and warnings are
    /// still printed).
    #[arg(short, long)]
    pub quiet: bool,
}

/// Options every command shares.
#[derive(Args)]
pub struct SceneArgs {
    /// Scene file, by extension: .scene (Appendix A format), .obj (with its MTL), .gltf or
    /// .glb, .dxf (with NAME.materials.toml) or .wrl (VRML97); the
    /// built-in Cornell box when omitted.
    pub scene: Option<PathBuf>,
    /// Multiply every coordinate of the scene file by this (0.001 reads a model in
    /// millimetres as metres). OBJ states no unit: its numbers are taken as metres, times
    /// SCALE. A .scene file's MAX_PATCH_AREA is scaled with it, so it meshes the same.
    #[arg(long, default_value_t = 1.0, value_name = "SCALE")]
    pub scale: f64,
    /// Override the scene's MAX_PATCH_AREA, in the units after --scale squared (the file's
    /// own MAX_PATCH_AREA is scaled by --scale^2; this one is taken as given).
    #[arg(long, value_name = "AREA")]
    pub max_area: Option<f64>,
    /// Override the scene's INTEGRAL_STEPS (points along each axis of each element, for
    /// the area, contour and analytic methods; 1 or more).
    #[arg(long, value_name = "K", value_parser = parse_steps)]
    pub steps: Option<u32>,
    #[command(flatten)]
    pub method: MethodArgs,
    /// No progress bars, timings or notes (errors and warnings are still printed).
    #[arg(short, long)]
    pub quiet: bool,
    /// Run even work estimated at about an hour or more (20 minutes to 2.5 hours by kind,
    /// at rates measured on two cores), which is refused otherwise: element pairs
    /// x INTEGRAL_STEPS^4 point pairs, Monte Carlo samples, hemicube resolution, and where
    /// the command draws an image, its pixels x --supersample^2 or --paths. Memory limits
    /// still hold.
    #[arg(long)]
    pub no_work_limit: bool,
}

/// How form factors are computed.
#[derive(Args, Clone)]
pub struct MethodArgs {
    /// Form-factor method [default: area]
    // No clap default, so that an explicit `--method area` can be told from none:
    // hierarchical radiosity, which ignores the method, warns about any given.
    #[arg(long, value_enum)]
    pub method: Option<MethodArg>,
    /// Hemicube resolution: cells across the top face (--method hemicube only).
    // Values are checked while parsing, whatever the method, as --steps is (QA of issue
    // #16: `--resolution 0` was refused with the hemicube and only "ignored" without it).
    #[arg(long, default_value_t = MethodArgs::RESOLUTION, value_name = "CELLS",
          value_parser = parse_resolution)]
    pub resolution: u32,
    /// Monte Carlo rays per element (--method montecarlo only).
    #[arg(long, default_value_t = MethodArgs::SAMPLES, value_name = "N",
          value_parser = parse_samples)]
    pub samples: u32,
    /// Monte Carlo generator seed (the same seed gives the same numbers; --method
    /// montecarlo only).
    #[arg(long, default_value_t = MethodArgs::SEED)]
    pub seed: u64,
}

impl MethodArgs {
    /// `--resolution`'s default.
    pub const RESOLUTION: u32 = 128;
    /// `--samples`'s default.
    pub const SAMPLES: u32 = 1024;
    /// `--seed`'s default.
    pub const SEED: u64 = 1;

    /// These flags with those the method does not use at their defaults (what the run
    /// does; see [`crate::setup::ignored_method_flags`]).
    pub fn without_unused(&self) -> MethodArgs {
        let method = self.method.unwrap_or(MethodArg::Area);
        MethodArgs {
            method: self.method,
            resolution: match method {
                MethodArg::Hemicube => self.resolution,
                _ => Self::RESOLUTION,
            },
            samples: match method {
                MethodArg::Montecarlo => self.samples,
                _ => Self::SAMPLES,
            },
            seed: match method {
                MethodArg::Montecarlo => self.seed,
                _ => Self::SEED,
            },
        }
    }
}

/// Options of commands that solve.
#[derive(Args)]
pub struct SolveOptions {
    /// Solver for (I - rho F) B = E.
    #[arg(long, value_enum, default_value_t = SolverArg(SolverKind::Auto))]
    pub solver: SolverArg,
    /// Where the solver stops. Gauss-Seidel: the relative residual (default 1e-9).
    /// Progressive: the unshot power as a fraction of the emitted power, in every band (the
    /// convergence value of Cohen et al. 1988; default 0.01 = 1 %). Hierarchical: the power
    /// still changing in a sweep as a fraction of the emitted power (default 1e-6). LU
    /// solves directly and takes none.
    #[arg(long, value_name = "TOL")]
    pub tolerance: Option<f64>,
    /// Dense solvers (auto, which then takes Gauss-Seidel, gauss-seidel, lu): read the form
    /// factors from this file (written by `radiosity formfactors`) instead of computing
    /// them; refused if it was made for another mesh or method, and with --solver
    /// progressive or hierarchical or --adapt-rounds, which compute their own.
    #[arg(long, value_name = "FILE")]
    pub form_factors: Option<PathBuf>,
    /// Hierarchical: the BF refinement threshold, relative to the mean radiosity (smaller is
    /// finer and slower).
    #[arg(long, default_value_t = 0.05, value_name = "E")]
    pub epsilon: f64,
    /// Hierarchical: nodes of at most this area (the units after --scale, squared) are not
    /// split (default: MAX_PATCH_AREA / 16).
    #[arg(long, value_name = "AREA")]
    pub min_area: Option<f64>,
    /// Hierarchical: leave out the final gather (each leaf then takes its ancestors'
    /// irradiance pushed down, as before the gather was added): faster, and visibly
    /// wrong where coarse links meet (bright concave corners, darker walls between).
    #[arg(long)]
    pub no_final_gather: bool,
    /// Hierarchical: the most points the final gather gathers at (the leaves along
    /// contacts always gather their own, beyond it); above it, the gather runs at coarser
    /// patches and the leaves under each take its light plus what finer links bring. Its
    /// time grows with this: at the default, the million-element building gathers at
    /// 236,916 points in about 110 s of CPU (BENCHMARKS.md), the Cornell box at --max-area
    /// 10 at its 176,191 leaves in about 8 s (README, two idle cores).
    #[arg(long, value_name = "N", default_value_t = radiosity::solve::GATHER_POINTS_DEFAULT,
          value_parser = parse_gather_points)]
    pub gather_points: usize,
    /// Dense solvers: rounds of adaptive subdivision after the first solve (each splits
    /// the elements whose luminance steps against a neighbour's, then solves again; 2 is a
    /// good start for furnished rooms); 0, the default, solves the mesh once. Not with
    /// --form-factors.
    #[arg(long, value_name = "N")]
    pub adapt_rounds: Option<u32>,
    /// Adaptive subdivision: a step between touching elements is split when it exceeds this
    /// fraction of the brighter one's luminance (and 5 % of white).
    #[arg(long, default_value_t = radiosity::mesh::DEFAULT_CONTRAST, value_name = "FRACTION")]
    pub adapt_contrast: f64,
    /// Adaptive subdivision: the refined mesh has at most this many elements (default: twice
    /// the mesh's, at most 20,000, and no more new form-factor pairs than n^2, about twice
    /// the first matrix's, or 4 million; given, only this limit holds).
    #[arg(long, value_name = "N")]
    pub adapt_max_elements: Option<usize>,
    /// Progressive: stop after this many shots even if the unshot power is still above
    /// --tolerance; the output then holds the light shot so far, and a note says how far it
    /// got.
    #[arg(long, default_value_t = 1_000_000, value_name = "N")]
    pub max_shots: usize,
}

#[derive(Clone, Copy, ValueEnum)]
pub enum MethodArg {
    /// The paper's double area integral, INTEGRAL_STEPS^2 points per element, a ray per
    /// point pair for occlusion.
    Area,
    /// Exact element-to-element form factors (the double contour integral); pairs that an
    /// occluder may block are scaled by the visible fraction of INTEGRAL_STEPS^2 point pairs.
    Contour,
    /// Lambert's exact point-to-polygon form factor at INTEGRAL_STEPS^2 receiver points,
    /// with rays to the source's points for occlusion.
    Analytic,
    /// Hemicube (Cohen and Greenberg 1985) rasterised on the CPU, --resolution; occlusion
    /// by depth buffer.
    Hemicube,
    /// Stratified Monte Carlo ray casting, --samples rays per element, --seed; occlusion by
    /// each ray's first hit.
    Montecarlo,
}

/// `--solver`: the library's [`SolverKind`], its names and help as the library gives them.
#[derive(Clone, Copy)]
pub struct SolverArg(pub SolverKind);

impl ValueEnum for SolverArg {
    fn value_variants<'a>() -> &'a [Self] {
        const ALL: [SolverArg; 5] = [
            SolverArg(SolverKind::ALL[0]),
            SolverArg(SolverKind::ALL[1]),
            SolverArg(SolverKind::ALL[2]),
            SolverArg(SolverKind::ALL[3]),
            SolverArg(SolverKind::ALL[4]),
        ];
        &ALL
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.0.name()).help(self.0.help()))
    }
}

impl std::fmt::Display for SolverArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ShadingArg {
    /// Vertex radiosities interpolated across elements (paper plate 2).
    Smooth,
    /// One colour per element (paper plate 1).
    Flat,
    /// Element edges (paper plate 4).
    Wireframe,
}

/// Where smooth shading takes the direct light from.
#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DirectLightArg {
    /// Gathered at every ray's hit point from the emitters (Lambert's exact form factor and
    /// shadow rays); the mesh gives only the indirect light: sharp shadows and contact lines.
    Gather,
    /// Interpolated from the mesh with the rest of the light (the paper's smooth shading).
    Mesh,
}

impl RayArgs {
    /// `--adaptive-contrast`'s default.
    pub const ADAPTIVE_CONTRAST: f64 = 0.02;

    /// `--direct-light`, or its default (gather).
    pub fn direct_light(&self) -> DirectLightArg {
        self.direct_light.unwrap_or(DirectLightArg::Gather)
    }
}

/// Exposure and gamma: the flags `render` and `pathtrace` share.
#[derive(Args)]
pub struct ToneArgs {
    /// Gamma: displayed = value^(1/gamma) (paper 2.7).
    #[arg(long, default_value_t = 2.2)]
    pub gamma: f64,
    /// Exposure: "auto" makes the mean radiosity of the brightest 2 % of the non-emitting
    /// area white (about 1 % of it clips; the same whatever the mesh and solver), a number
    /// multiplies radiosities by it.
    #[arg(long, default_value = "auto", value_parser = parse_exposure)]
    pub exposure: Exposure,
}

/// Where the camera is and the size of its image: the flags `render` and `pathtrace`
/// share, so that a render and a path trace of one scene line up pixel for pixel.
#[derive(Args)]
pub struct CameraArgs {
    /// Eye position "x,y,z" (default: the scene's camera, or one that frames the scene).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = parse_vec3)]
    pub eye: Option<DVec3>,
    /// Point looked at "x,y,z" (default: the scene's camera's, or the automatic camera's,
    /// as for --eye).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = parse_vec3)]
    pub look_at: Option<DVec3>,
    /// Up direction "x,y,z" (default: the scene's camera's, or +y unless the scene reads as
    /// z-up, by its extent and its lights: README, `render` options; the camera is printed).
    #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = parse_vec3)]
    pub up: Option<DVec3>,
    /// Vertical field of view in degrees (default: the scene's camera's, or one that
    /// frames the scene).
    #[arg(long, value_name = "DEGREES", allow_hyphen_values = true)]
    pub fov: Option<f64>,
    /// Image width in pixels (default 512; --height alone sets both: the picture stays
    /// square).
    #[arg(long, value_parser = parse_at_least_1)]
    pub width: Option<u32>,
    /// Image height in pixels (default 512; --width alone sets both).
    #[arg(long, value_parser = parse_at_least_1)]
    pub height: Option<u32>,
}

impl CameraArgs {
    /// The default image side in pixels.
    pub const DEFAULT_SIDE: u32 = 512;

    /// The image's width and height: the two flags, or the one given for both (QA of issue
    /// #16: `--width 64` alone gave a 64 x 512 picture, the box a sliver in its middle).
    pub fn size(&self) -> (u32, u32) {
        match (self.width, self.height) {
            (Some(w), Some(h)) => (w, h),
            (Some(side), None) | (None, Some(side)) => (side, side),
            (None, None) => (Self::DEFAULT_SIDE, Self::DEFAULT_SIDE),
        }
    }
}

/// How many rays a pixel gets and where smooth shading's direct light comes from: the flags
/// `render` and `pathtrace --compare` share, so that the comparison judges what `render`
/// draws. (The path tracer averages over the whole pixel, so one ray through the centre
/// would count edge aliasing as error.)
#[derive(Args)]
pub struct RayArgs {
    /// Rays per pixel along each axis, at most (1 to 16): 2 or more antialiases edges. An
    /// even N above 2 is adaptive (see --adaptive-contrast); 1 casts one ray through each
    /// pixel centre.
    #[arg(long, default_value_t = 8, value_name = "N", value_parser = parse_supersample)]
    pub supersample: u32,
    /// Adaptive antialiasing (an even --supersample N above 2, smooth or flat shading): each
    /// pixel casts four rays first; where they see different surfaces (an object's edge) it
    /// casts all N x N, where their luminances spread by more than this fraction of the
    /// brightest of them (a shadow edge) N/2 x N/2, elsewhere the four are the pixel. 0
    /// casts all N x N everywhere.
    #[arg(long, default_value_t = RayArgs::ADAPTIVE_CONTRAST, value_name = "FRACTION", value_parser = parse_fraction)]
    pub adaptive_contrast: f64,
    /// Smooth shading's direct light: gathered per ray, or from the mesh [default: gather].
    // No clap default, so that a `--direct-light gather` that the shading ignores can be
    // warned of (QA pass 12 of #16); `RayArgs::direct_light` gives the default.
    #[arg(long, value_enum, value_name = "DIRECT_LIGHT")]
    pub direct_light: Option<DirectLightArg>,
}

#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub solve: SolveOptions,
    /// Output image: .png, or .exr for linear radiance (default: cornell.png for the
    /// built-in box, else the scene's name with .png).
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Shading.
    #[arg(long, value_enum, default_value_t = ShadingArg::Smooth)]
    pub shading: ShadingArg,
    #[command(flatten)]
    pub tone: ToneArgs,
    #[command(flatten)]
    pub camera: CameraArgs,
    #[command(flatten)]
    pub rays: RayArgs,
    /// Progressive: write the picture as it converges to DIR/shot-00010.png and so on, every
    /// --snapshot-every shots (with the ambient term added for display).
    #[arg(long, value_name = "DIR")]
    pub snapshots: Option<PathBuf>,
    /// Progressive: shots between snapshots (with --snapshots).
    #[arg(long, default_value_t = RenderArgs::SNAPSHOT_EVERY, value_name = "N")]
    pub snapshot_every: usize,
    /// Draw the illuminance (lux) on the surfaces in false colour, dark blue at 0 to red at
    /// the top of the scale, with a scale bar (values and unit) on the right, instead of
    /// the shaded view (a PNG; smooth or flat shading).
    #[arg(long)]
    pub false_colour: bool,
    /// With --false-colour: the illuminance at the top of the scale, in lux (default: the
    /// largest on any element, rounded up to 4-8 round steps: 150.3 gives 160); brighter
    /// surfaces take the top colour.
    #[arg(long, value_name = "LUX")]
    pub lux_max: Option<f64>,
}

impl RenderArgs {
    /// `--snapshot-every`'s default.
    pub const SNAPSHOT_EVERY: usize = 10;
}

#[derive(Args)]
pub struct PathTraceArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub solve: SolveOptions,
    #[command(flatten)]
    pub tone: ToneArgs,
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Output of the path-traced view, PNG or, by extension, .exr (linear radiance)
    /// (default: <scene>-pathtrace.png). With --compare
    /// the radiosity render and the error map go beside it, as <output>-radiosity.png
    /// (.exr for an .exr output) and <output>-error.png.
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Paths per pixel (at least 2, for a standard error): the noise falls as 1/sqrt(N).
    #[arg(long, default_value_t = 256, value_name = "N", value_parser = parse_at_least_2)]
    pub paths: u32,
    /// Seed of the paths: the same seed gives the same image, bit for bit, on any number of
    /// threads. (--seed is the Monte Carlo form factors' seed.)
    #[arg(long, default_value_t = 1, value_name = "S")]
    pub path_seed: u64,
    /// The most diffuse reflections a path may make (Russian roulette ends almost all paths
    /// long before); 0 shows the emitters only.
    #[arg(long, default_value_t = 256, value_name = "N")]
    pub max_bounces: u32,
    /// Russian roulette starts after this many reflections (unbiased for any value).
    #[arg(long, default_value_t = 3, value_name = "N")]
    pub roulette_after: u32,
    /// No light sampling (next-event estimation): the plain path tracer, which finds a light
    /// only by bouncing into it; far noisier under small lights.
    #[arg(long)]
    pub no_light_sampling: bool,
    /// Also solve the scene by radiosity (with the solve flags, as `render`), render it with
    /// the same camera, and print the pixel RMS, bias and largest difference of its
    /// luminance from the path-traced view's (pixels that show an emitter left out) beside
    /// the path tracer's own noise. Both images are written with one exposure (auto: the
    /// radiosity solution's). The meshing, form-factor and solver flags (--max-area,
    /// --steps, --method, --solver, ...) act on this solve only; the path tracer traces the
    /// scene's polygons.
    #[arg(long)]
    pub compare: bool,
    /// --compare: the radiosity render's shading.
    #[arg(long, value_enum, default_value_t = ShadingArg::Smooth)]
    pub shading: ShadingArg,
    /// --compare: the radiosity render's rays, as for `render` (--supersample,
    /// --adaptive-contrast and --direct-light act on that render only).
    #[command(flatten)]
    pub rays: RayArgs,
    /// --compare: the relative error that saturates the error map's colours (blue: the
    /// radiosity render is darker, red: brighter).
    #[arg(long, default_value_t = 0.2, value_name = "FRACTION", value_parser = parse_positive)]
    pub error_scale: f64,
    /// Write the path-traced view (linear radiosity, standard errors, the emitter mask, the
    /// camera and settings) to this OpenEXR file, to be read back with --reference.
    #[arg(long, value_name = "FILE.exr", conflicts_with = "reference")]
    pub save_reference: Option<PathBuf>,
    /// Read the path-traced view from this file (written by --save-reference) instead of
    /// tracing it; refused if it was traced from another scene, camera or image size.
    #[arg(long, value_name = "FILE.exr")]
    pub reference: Option<PathBuf>,
}

#[derive(Args)]
pub struct ExportArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub solve: SolveOptions,
    /// Output file, by its extension: .glb (binary glTF) or .gltf (JSON, its buffer in a
    /// .bin file beside it): the solved mesh, radiosity as vertex colours on unlit
    /// materials; .obj: the scene's surfaces (not the mesh) with an .mtl file beside it.
    #[arg(short, long, value_name = "FILE")]
    pub output: PathBuf,
    /// glTF: the factor vertex colours are radiosity times (then clamped to 1): "auto", as
    /// for `render` (the mean radiosity of the brightest 2 % of the non-emitting area is
    /// white), or a number. Printed and written to the file's asset.extras.
    #[arg(long, default_value = "auto", value_parser = parse_exposure)]
    pub exposure: Exposure,
    /// glTF: the camera node (as `render`'s camera for the same flags).
    #[command(flatten)]
    pub camera: CameraArgs,
}

#[derive(Args)]
pub struct FormFactorArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output file, named *.ff (default: the scene's name with .ff): the matrix in this
    /// program's binary format, read back by --form-factors.
    #[arg(short, long, value_name = "FILE.ff")]
    pub output: Option<PathBuf>,
}

#[derive(Args)]
pub struct SolveArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub solve: SolveOptions,
    /// Output file, named *.csv (CSV) or *.json (JSON) (default: the scene's name with
    /// .csv).
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Also write the per-surface report to this CSV file: one row per input surface with
    /// its area and the area-weighted mean, min and max radiosity per band over its
    /// elements and the mean's luminance (Rec. 709), under a comment line giving the units.
    #[arg(long, value_name = "FILE.csv")]
    pub report: Option<PathBuf>,
}

#[derive(Args)]
pub struct IlluminanceArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub solve: SolveOptions,
    /// Calculation points: a CSV with the header name,x,y,z,nx,ny,nz (scene units; the
    /// normal is the direction the meter faces).
    #[arg(long, value_name = "P.csv", conflicts_with = "grid")]
    pub points: Option<PathBuf>,
    /// A rectangular grid instead: corners x0,y0,z0 and x1,y1,z1 (equal in at least one
    /// axis) and the spacing; points from the first corner every SPACING up to the second.
    #[arg(long, value_name = "X0,Y0,Z0:X1,Y1,Z1:SPACING", allow_hyphen_values = true,
          value_parser = parse_grid)]
    pub grid: Option<(DVec3, DVec3, f64)>,
    /// The normal of every grid point, required with --grid: 0,0,1 for a horizontal work
    /// plane in a z-up scene, 0,1,0 in a y-up one such as the Cornell box (scenes come both
    /// ways up, so no default would be right for all).
    #[arg(long, value_name = "NX,NY,NZ", allow_hyphen_values = true, value_parser = parse_vec3)]
    pub normal: Option<DVec3>,
    /// Output CSV: name,x,y,z,nx,ny,nz,direct_lux,indirect_lux,total_lux.
    #[arg(short, long, value_name = "OUT.csv")]
    pub output: PathBuf,
    /// Also draw the grid's total illuminance as a PNG (coloured cells with their values and
    /// a scale bar in lx).
    #[arg(long, value_name = "FILE.png")]
    pub png: Option<PathBuf>,
}

#[derive(Args)]
pub struct CheckArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub solve: SolveOptions,
    /// Instead of checking a scene (give none), print the accuracy table: every form-factor
    /// method against closed forms (opposed and perpendicular squares, coaxial discs, a
    /// small element under a rectangle), its row-sum error in a closed box, its reciprocity
    /// error and its time, as Markdown. --max-area sets the elements' size (default 1/64
    /// of the unit squares); about 8 s on two cores, a line per method on stderr meanwhile.
    #[arg(long)]
    pub compare_methods: bool,
}

#[derive(Args)]
pub struct CompareArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub solve: SolveOptions,
    /// Only time the solver (no dense reference).
    #[arg(long)]
    pub no_reference: bool,
}

#[derive(Args)]
pub struct BenchArgs {
    /// Scene file, by extension: .scene (Appendix A format), .obj (with its MTL), .gltf or
    /// .glb, .dxf (with NAME.materials.toml) or .wrl (VRML97); the
    /// built-in Cornell box when omitted.
    pub scene: Option<PathBuf>,
    /// Multiply every coordinate of the scene file by this (0.001 reads a model in
    /// millimetres as metres). OBJ states no unit: its numbers are taken as metres, times
    /// SCALE. A .scene file's MAX_PATCH_AREA is scaled with it, so it meshes the same.
    #[arg(long, default_value_t = 1.0, value_name = "SCALE")]
    pub scale: f64,
    #[command(flatten)]
    pub method: MethodArgs,
    /// MAX_PATCH_AREA values to time, one table row each (several values: separated by
    /// commas, as separate arguments, or the option repeated); the scene's own when
    /// omitted.
    #[arg(long, value_name = "AREA", num_args = 1.., value_delimiter = ',', value_parser = parse_positive)]
    pub max_area: Vec<f64>,
    /// Override the scene's INTEGRAL_STEPS.
    #[arg(long, value_name = "K", value_parser = parse_steps)]
    pub steps: Option<u32>,
    /// Runs per configuration; the table shows the median of each column. Runs that would
    /// take more than an hour at the first run's time are refused after it (see
    /// --no-work-limit).
    #[arg(long, default_value_t = 5, value_name = "N", value_parser = parse_at_least_1)]
    pub repeat: u32,
    /// Solver for (I - rho F) B = E.
    #[arg(long, value_enum, default_value_t = SolverArg(SolverKind::Auto))]
    pub solver: SolverArg,
    /// Where the solver stops (as for `render --tolerance`: 1e-9 residual for Gauss-Seidel,
    /// 0.01 unshot for progressive, 1e-6 changing power for hierarchical).
    #[arg(long, value_name = "TOL")]
    pub tolerance: Option<f64>,
    /// Image width and height in pixels (default 512); --width or --height given beside it
    /// sets that side alone.
    #[arg(long, value_name = "PIXELS", value_parser = parse_at_least_1)]
    pub size: Option<u32>,
    /// Image width in pixels; without --size or --height it sets both sides, as for
    /// `render`.
    #[arg(long, value_parser = parse_at_least_1)]
    pub width: Option<u32>,
    /// Image height in pixels; without --size or --width it sets both sides, as for
    /// `render`.
    #[arg(long, value_parser = parse_at_least_1)]
    pub height: Option<u32>,
    /// The rays a pixel and the direct light, as for `render` and with its defaults, so that
    /// the render column times what `render` draws (QA of issue #16: bench cast one ray a
    /// pixel from the mesh alone; `--supersample 1 --direct-light mesh` is the paper's
    /// rendering, which the tables against the paper use).
    #[command(flatten)]
    pub rays: RayArgs,
    /// Hierarchical: the BF refinement threshold (as for `render --epsilon`).
    #[arg(long, default_value_t = 0.05, value_name = "E")]
    pub epsilon: f64,
    /// Hierarchical: the minimum node area (as for `render --min-area`).
    #[arg(long, value_name = "AREA")]
    pub min_area: Option<f64>,
    /// Only the table: no note on what was timed (errors and warnings are still printed).
    #[arg(short, long)]
    pub quiet: bool,
    /// Time even work estimated at about an hour or more (20 minutes to 2.5 hours by kind,
    /// at rates measured on two cores), refused otherwise before the first run
    /// (as for `render --no-work-limit`: element pairs x INTEGRAL_STEPS^4 point pairs,
    /// Monte Carlo samples, hemicube resolution, pixels x --supersample^2), and --repeat
    /// runs of a configuration past an hour at its first run's time, refused otherwise after
    /// that run. Memory limits still hold.
    #[arg(long)]
    pub no_work_limit: bool,
}

/// Options of `radiosity view`.
#[derive(Args)]
#[cfg_attr(not(feature = "viewer"), allow(dead_code))]
pub struct ViewArgs {
    /// Scene file, by extension: .scene (Appendix A format), .obj (with its MTL), .gltf or
    /// .glb, .dxf (with NAME.materials.toml) or .wrl (VRML97); the
    /// built-in Cornell box when omitted.
    pub scene: Option<PathBuf>,
    /// Multiply every coordinate of the scene file by this (0.001 reads a model in
    /// millimetres as metres). OBJ states no unit: its numbers are taken as metres, times
    /// SCALE. A .scene file's MAX_PATCH_AREA is scaled with it, so it meshes the same.
    #[arg(long, default_value_t = 1.0, value_name = "SCALE")]
    pub scale: f64,
    /// Override the scene's MAX_PATCH_AREA, in the units after --scale squared (the file's
    /// own MAX_PATCH_AREA is scaled by --scale^2; this one is taken as given).
    #[arg(long, value_name = "AREA")]
    pub max_area: Option<f64>,
    /// Override the scene's INTEGRAL_STEPS.
    #[arg(long, value_name = "K", value_parser = parse_steps)]
    pub steps: Option<u32>,
    /// Always solve by progressive refinement (no form-factor matrix; colour edits re-run
    /// it). By default the dense solve is used up to 6,000 elements (see --dense).
    #[arg(long, conflicts_with = "dense")]
    pub progressive: bool,
    /// Compute the dense form-factor matrix whenever it fits (up to 20,000 elements), so
    /// edits are quick re-solves; by default only up to 6,000 elements, beyond which
    /// progressive refinement shows light sooner.
    #[arg(long)]
    pub dense: bool,
    /// The solver: auto (the dense matrix up to 6,000 elements, or 20,000 with --dense,
    /// progressive refinement beyond; --progressive always progressive), dense or
    /// gauss-seidel (Gauss-Seidel on the cached matrix whenever it fits, else progressive),
    /// lu (likewise, LU), progressive, hierarchical (hierarchical radiosity with clustering,
    /// --epsilon, --min-area; the window shows its leaves and an edit re-runs it).
    #[arg(
        long,
        value_name = "SOLVER",
        default_value = "auto",
        conflicts_with_all = ["dense", "progressive"],
        value_parser = parse_view_solver
    )]
    pub solver: SolverKind,
    /// Hierarchical: the BF refinement threshold (as for `render --epsilon`).
    #[arg(long, default_value_t = 0.05, value_name = "E")]
    pub epsilon: f64,
    /// Hierarchical: the minimum node area (default: MAX_PATCH_AREA / 16).
    #[arg(long, value_name = "AREA")]
    pub min_area: Option<f64>,
    /// Open the window, draw `--frames` frames of the solved scene, save the window to this
    /// PNG and exit.
    #[arg(long, value_name = "FILE")]
    pub screenshot: Option<PathBuf>,
    /// Frames drawn before `--screenshot`.
    #[arg(long, default_value_t = 30, value_name = "N")]
    pub frames: u32,
    /// Show the modeller panel in the `--screenshot` (the window always shows it otherwise).
    #[arg(long)]
    pub panel: bool,
    /// The shading the window starts with: smooth, flat or wireframe.
    #[arg(long, default_value = "smooth", value_name = "MODE", value_parser = parse_shading)]
    pub shading: Shading,
    /// Select a surface (as a click on it would): the one named so, else the first whose
    /// name starts with this that can be seen (not a face pressed against another, like the
    /// base of furniture standing on the floor).
    #[arg(long, value_name = "NAME")]
    pub select: Option<String>,
    /// No window: measure frame time offscreen (Cornell box and a tiled scene of
    /// `--bench-triangles`) and edit-to-picture time at `--bench-elements`, print Markdown.
    #[arg(long)]
    pub bench: bool,
    /// Triangles of the large frame-time scene, rounded up to whole copies of a Cornell box
    /// of about 10,000 elements (some 19,000 triangles each; at least one copy); 0 skips it.
    #[arg(long, default_value_t = 1_000_000, value_name = "N")]
    pub bench_triangles: usize,
    /// Element counts for edit-to-picture timing (comma-separated): the Cornell box is
    /// meshed to about each (the table gives the count reached).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "1000,5000,20000",
        value_name = "N,.."
    )]
    pub bench_elements: Vec<usize>,
    /// Frames timed per scene.
    #[arg(long, default_value_t = 30, value_name = "N")]
    pub bench_frames: u32,
    /// No notes (what a --screenshot wrote, --bench's line per measurement); errors and
    /// warnings are still printed, --bench's tables too.
    #[arg(short, long)]
    pub quiet: bool,
}

// Value parsers. Their message says what to give; [`value_error`] puts the flag and the
// value before it ("--eye 1,2: give three numbers ...").

/// The reason a value parser gave, with the standard library's parse errors put in the
/// words the project's own parsers use ("give a whole number", "give a number"); `value`
/// is the text given (a minus sign before an unsigned number is "at least 0").
pub fn plain_number_reason(value: &str, reason: &str) -> String {
    const WORDS: [(&str, &str); 5] = [
        ("invalid digit found in string", "give a whole number"),
        (
            "cannot parse integer from empty string",
            "give a whole number",
        ),
        (
            "number too large to fit in target type",
            "give a smaller whole number",
        ),
        (
            "number too small to fit in target type",
            "give a whole number of at least 0",
        ),
        ("invalid float literal", "give a number"),
    ];
    // A negative value for an unsigned flag: Rust's "invalid digit" is the minus sign.
    if value.trim_start().starts_with('-') && reason.contains("invalid digit found in string") {
        return "give a whole number of at least 0".to_string();
    }
    // clap's range check: "-1 is not in 0..=4294967295", "0 is not in 1..=18446744073709551615".
    if let Some((_, range)) = reason.split_once(" is not in ") {
        if let Some((lo, hi)) = range.trim().split_once("..=") {
            let unbounded = [u32::MAX as u64, u64::MAX, i64::MAX as u64]
                .iter()
                .any(|m| hi.parse::<u64>() == Ok(*m));
            // Past the top ("--max-bounces 5000000000" for a u32): "at least 0" would be
            // true of the value given (QA of issue #16), so the top is named.
            // A run of digits too long even for a u128 is past any top too.
            let digits = value.trim().trim_start_matches('+');
            let past_top = match (digits.parse::<u128>(), hi.parse::<u128>()) {
                (Ok(v), Ok(h)) => v > h,
                (Err(_), Ok(_)) => !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()),
                _ => false,
            };
            return if unbounded && !past_top {
                format!("give a whole number of at least {lo}")
            } else {
                format!("give a whole number from {lo} to {hi}")
            };
        }
    }
    WORDS
        .iter()
        .find(|(from, _)| reason.contains(from))
        .map_or_else(|| reason.to_string(), |(_, to)| to.to_string())
}

/// A wrong flag value caught while parsing, in the frame of the checks made after it
/// (`--steps 0: give ...`, exit 1; QA of issue #16: clap's "invalid value '0' for '--steps
/// <K>': ..." with exit 2 stood beside "--max-area 0: give ..." with exit 1 for the same
/// kind of mistake). `None` for the errors that are not about a value (an unknown flag, a
/// missing value), which keep clap's usage message.
pub fn value_error(e: &clap::Error) -> Option<String> {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    let text = |kind| match e.get(kind) {
        Some(ContextValue::String(s)) => Some(s.clone()),
        _ => None,
    };
    let arg = text(ContextKind::InvalidArg)?;
    let value = text(ContextKind::InvalidValue)?;
    // "--steps <K>" or "-o <FILE>" is named by its flag; a positional "[SCENE]" as it is.
    let flag = match arg.split_whitespace().next() {
        Some(f) if f.starts_with('-') => f.to_string(),
        _ => arg.trim_matches(['[', ']', '<', '>', '.']).to_string(),
    };
    let reason = match e.kind() {
        ErrorKind::ValueValidation => {
            let reason = std::error::Error::source(e)?.to_string();
            plain_number_reason(&value, &reason)
        }
        // An empty value where one is needed (`-o ""`: QA of issue #16, "give one of "
        // with nothing after it): named by the flag's value name. clap reports a flag given
        // no value at all (`render -o` at the end) the same way; that keeps clap's usage
        // message (exit 2), told apart by whether an empty argument was typed.
        ErrorKind::InvalidValue if value.is_empty() => {
            if !std::env::args_os().skip(1).any(|a| a.is_empty()) {
                return None;
            }
            let name = arg
                .split_once('<')
                .and_then(|(_, rest)| rest.split_once('>'))
                .map(|(name, _)| name.to_string())
                .unwrap_or_else(|| arg.trim_matches(['[', ']', '.']).to_string());
            format!("empty; give a {name} name")
        }
        ErrorKind::InvalidValue => {
            let valid = match e.get(ContextKind::ValidValue) {
                Some(ContextValue::Strings(v)) if !v.is_empty() => v.join(", "),
                _ => return None,
            };
            match text(ContextKind::SuggestedValue) {
                Some(near) => format!("give one of {valid} (did you mean {near}?)"),
                None => format!("give one of {valid}"),
            }
        }
        _ => return None,
    };
    let value = if value.is_empty() {
        "\"\"".to_string()
    } else {
        value
    };
    Some(format!("{flag} {value}: {reason}"))
}

/// A whole number of at least `min`, refused in the words the other flags use (QA of
/// issue #16: clap's own "0 is not in 1..=4294967295").
fn whole_number_at_least(text: &str, min: u32) -> Result<u32, String> {
    match text.trim().parse::<u32>() {
        Ok(n) if n >= min => Ok(n),
        _ => Err(format!(
            "give {}",
            at_least_words(text, min.into(), u32::MAX.into())
        )),
    }
}

/// "a whole number of at least MIN", or "from MIN to MAX" for a whole number past `max`
/// (QA of issue #16: `--width 4294967297` was told to be "at least 1").
fn at_least_words(text: &str, min: u64, max: u64) -> String {
    let digits = text.trim();
    let too_large = !digits.is_empty()
        && digits.chars().all(|c| c.is_ascii_digit())
        && digits.parse::<u64>().map_or(true, |n| n > max);
    if too_large {
        format!("a whole number from {min} to {max}")
    } else {
        format!("a whole number of at least {min}")
    }
}

/// A whole number from `min` to `max`, in the same words (clap's range parser said
/// "0 is not in 1..=10000").
fn whole_number_in(text: &str, min: u32, max: u32) -> Result<u32, String> {
    match text.trim().parse::<u32>() {
        Ok(n) if (min..=max).contains(&n) => Ok(n),
        _ => Err(format!("give a whole number from {min} to {max}")),
    }
}

/// [`whole_number_in`] 1 to 16: rays per pixel along each axis.
pub fn parse_supersample(text: &str) -> Result<u32, String> {
    whole_number_in(text, 1, 16)
}

/// `--steps`: the points along each axis of an element, 1 or more.
pub fn parse_steps(text: &str) -> Result<u32, String> {
    whole_number_at_least(text, 1).map_err(|_| {
        format!(
            "give the points along each axis of an element, {}",
            at_least_words(text, 1, u32::MAX.into())
        )
    })
}

/// `--resolution`: the hemicube's cells along a side, 2 to 16,384.
pub fn parse_resolution(text: &str) -> Result<u32, String> {
    whole_number_in(text, 2, 16_384).map_err(|_| {
        "give the hemicube's cells along a side, a whole number from 2 to 16384".into()
    })
}

/// `--samples`: Monte Carlo rays per element, 1 or more.
pub fn parse_samples(text: &str) -> Result<u32, String> {
    whole_number_at_least(text, 1).map_err(|_| {
        format!(
            "give the Monte Carlo rays per element, {}",
            at_least_words(text, 1, u32::MAX.into())
        )
    })
}

/// `--gather-points`: the most points the final gather gathers at, 1 or more.
pub fn parse_gather_points(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "give the most points the final gather gathers at, {} (--no-final-gather leaves \
             the gather out)",
            at_least_words(text, 1, usize::MAX as u64)
        )),
    }
}

/// [`whole_number_at_least`] 1: image sizes.
pub fn parse_at_least_1(text: &str) -> Result<u32, String> {
    whole_number_at_least(text, 1)
}

/// [`whole_number_at_least`] 2: paths a pixel (a standard error needs two).
pub fn parse_at_least_2(text: &str) -> Result<u32, String> {
    whole_number_at_least(text, 2)
}

/// `--eye`, `--look-at`, `--up`: three finite numbers "x,y,z".
pub fn parse_vec3(text: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let values: Vec<f64> = parts.iter().filter_map(|p| p.parse::<f64>().ok()).collect();
    if parts.len() != 3 || values.len() != 3 {
        return Err("give three numbers \"x,y,z\"".into());
    }
    // QA of issue #16: "1e400" reads as a number, past the largest a double holds.
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(format!(
            "give three numbers \"x,y,z\" ({} is not a finite number)",
            parts[k]
        ));
    }
    Ok(DVec3::new(values[0], values[1], values[2]))
}

/// `illuminance --grid`: "x0,y0,z0:x1,y1,z1:spacing".
pub fn parse_grid(text: &str) -> Result<(DVec3, DVec3, f64), String> {
    let parts: Vec<&str> = text.split(':').collect();
    let [a, b, s] = parts.as_slice() else {
        return Err("give \"x0,y0,z0:x1,y1,z1:spacing\" (two corners and a spacing)".into());
    };
    let a = parse_vec3(a).map_err(|e| format!("the first corner: {e}"))?;
    let b = parse_vec3(b).map_err(|e| format!("the second corner: {e}"))?;
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok((a, b, v)),
        _ => Err(format!(
            "give a spacing above 0 after the second ':', not \"{s}\""
        )),
    }
}

/// `render --exposure`: "auto" (any case) or a positive number.
pub fn parse_exposure(text: &str) -> Result<Exposure, String> {
    if text.eq_ignore_ascii_case("auto") {
        return Ok(Exposure::Auto);
    }
    match text.parse::<f64>() {
        Ok(s) if s > 0.0 && s.is_finite() => Ok(Exposure::Fixed(s)),
        _ => Err("give \"auto\" or a number above 0".into()),
    }
}

/// A positive finite number.
pub fn parse_positive(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x > 0.0 && x.is_finite() => Ok(x),
        _ => Err("give a number above 0".into()),
    }
}

/// A number of at least 0 (`--adaptive-contrast`).
pub fn parse_fraction(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x >= 0.0 && x.is_finite() => Ok(x),
        _ => Err("give a number of at least 0".into()),
    }
}

/// `view --solver`: the library's solver names, and `dense`, the window's name for
/// Gauss-Seidel on the cached matrix.
pub fn parse_view_solver(text: &str) -> Result<SolverKind, String> {
    match text {
        "dense" => Ok(SolverKind::GaussSeidel),
        // The library's list leaves out `dense`, which only the window takes (QA of issue
        // #16); the flag and the value are named by [`value_error`].
        name => name.parse::<SolverKind>().map_err(|_| {
            "give one of auto, dense, lu, gauss-seidel, progressive, hierarchical".to_string()
        }),
    }
}

/// `view --shading`: smooth, flat or wireframe.
pub fn parse_shading(text: &str) -> Result<Shading, String> {
    match text {
        "smooth" => Ok(Shading::Smooth),
        "flat" => Ok(Shading::Flat),
        "wireframe" => Ok(Shading::Wireframe),
        _ => Err("give one of smooth, flat, wireframe".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_are_three_finite_numbers() {
        assert_eq!(parse_vec3("1, -2.5,3e1"), Ok(DVec3::new(1.0, -2.5, 30.0)));
        for bad in ["1,2", "1,2,3,4", "1,x,3", "1,inf,3", "1,NaN,3", ""] {
            let err = parse_vec3(bad).unwrap_err();
            assert!(err.contains("three numbers \"x,y,z\""), "{err}");
        }
    }

    #[test]
    fn exposure_is_auto_or_a_positive_number() {
        assert_eq!(parse_exposure("AUTO"), Ok(Exposure::Auto));
        assert_eq!(parse_exposure("2.5"), Ok(Exposure::Fixed(2.5)));
        for bad in ["bright", "0", "-1", "inf"] {
            let err = parse_exposure(bad).unwrap_err();
            assert!(err.contains("give \"auto\" or a number above 0"), "{err}");
        }
    }

    #[test]
    fn view_solver_and_shading_names() {
        assert_eq!(parse_view_solver("dense"), Ok(SolverKind::GaussSeidel));
        assert_eq!(parse_view_solver("lu"), Ok(SolverKind::Lu));
        assert!(parse_view_solver("fast")
            .unwrap_err()
            .contains("give one of auto, dense"));
        assert_eq!(parse_shading("flat"), Ok(Shading::Flat));
        assert!(parse_shading("toon").unwrap_err().contains("wireframe"));
    }
}
