//! # radiosity-viewer
//!
//! The walkthrough window and modeller of the `radiosity` renderer (paper sections 2.6,
//! 3.3 and 3.5): a solved scene in perspective, walked through with the keyboard and
//! mouse, its surfaces' reflectance and emission edited with colour pickers and re-solved
//! from the cached form factors while the window stays live.
//!
//! * [`run`] opens the window ([`ViewerOptions`]: scene, screenshot, panel).
//! * [`gpu`]: the wgpu pipeline, shared by the window and by [`gpu::render_offscreen`],
//!   which returns pixels without any window (tests, screenshots, benchmarks).
//! * [`camera::CameraController`]: the walking camera, a plain struct.
//! * [`model`]: the edited scene with undo.
//! * [`worker`]: the solve thread, on the library's solvers (dense with cached form
//!   factors and warm-started Gauss-Seidel re-solves, or progressive
//!   refinement for large scenes), sending intermediate solutions to the window.
//! * [`bench`]: frame time and edit-to-picture measurements.
//!
//! The core library (`radiosity`) has no window or GPU dependency; everything of that kind
//! is here.
//!
//! ```no_run
//! let scene = radiosity::scene::cornell_box().scene;
//! let mesh = radiosity::mesh::mesh_scene(&scene, 1000.0).unwrap();
//! let e: Vec<[f64; 3]> = mesh
//!     .elements
//!     .iter()
//!     .map(|el| scene.surfaces[el.surface as usize].emission.0)
//!     .collect();
//! let camera = radiosity::render::Camera::for_scene(&scene, 256, 256);
//! let (image, adapter) = radiosity_viewer::gpu::render_offscreen(
//!     &mesh, &e, &[], &camera, &Default::default()).unwrap();
//! println!("{} x {} on {adapter}", image.width(), image.height());
//! ```
#![deny(missing_docs)]

mod app;
pub mod bench;
pub mod camera;
pub mod gpu;
pub mod model;
pub mod worker;

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use radiosity::mesh::MeshSettings;
use radiosity::pipeline::Overrides;
use radiosity::scene::{Scene, SceneFile};

/// What to show and how.
#[derive(Clone, Debug)]
pub struct ViewerOptions {
    /// The scene.
    pub scene: Scene,
    /// Its file's settings: the scene is meshed with them (overrides applied) and saved
    /// with them (as they are).
    pub settings: MeshSettings,
    /// Its file (`None` for the built-in Cornell box); "save" writes beside the current
    /// directory's `<stem>-edited.scene` unless another path is typed
    /// ([`model::default_save_path`]).
    pub path: Option<PathBuf>,
    /// `--max-area` and `--steps`, applied to `settings` for meshing, never saved.
    pub overrides: Overrides,
    /// The solver (see [`worker::ViewSolver`] for the window's `auto`).
    pub solver: worker::ViewSolver,
    /// Save a screenshot of the whole window here after `frames` frames of the solved
    /// scene, then close.
    pub screenshot: Option<PathBuf>,
    /// Frames to draw before the screenshot.
    pub frames: u32,
    /// Show the modeller panel in the screenshot (it is always shown otherwise).
    pub panel: bool,
    /// Window size in points.
    pub size: [f32; 2],
    /// Select the surface named so, or the first that can be seen whose name starts with
    /// this, once the mesh is ready ([`model::select_by_name`]; for screenshots of the
    /// modeller).
    pub select: Option<String>,
    /// The shading the window starts with.
    pub shading: radiosity::render::Shading,
}

impl ViewerOptions {
    /// The defaults for the scene and settings of `file` (read from `path`): the window's
    /// auto solver, no overrides, no screenshot, 1280 x 800.
    pub fn new(file: SceneFile, path: Option<PathBuf>) -> ViewerOptions {
        ViewerOptions {
            scene: file.scene,
            settings: file.settings,
            path,
            overrides: Overrides::default(),
            solver: worker::ViewSolver::auto(),
            screenshot: None,
            frames: 30,
            panel: false,
            size: [1280.0, 800.0],
            select: None,
            shading: radiosity::render::Shading::Smooth,
        }
    }
}

/// Why the window could not run.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// No display to open a window on.
    #[error(
        "no display: neither DISPLAY nor WAYLAND_DISPLAY is set, so no window can be opened. \
         Run `radiosity view` in a desktop session, or headless under Xvfb: \
         `apt-get install xvfb` then `xvfb-run -s \"-screen 0 1280x800x24\" radiosity view ...` \
         (`radiosity render` makes images without any window)"
    )]
    NoDisplay,
    /// No usable graphics adapter.
    #[error(transparent)]
    Gpu(#[from] gpu::GpuError),
    /// DISPLAY is set but no X server answers there.
    #[error(
        "the display could not be opened: no X server answers at DISPLAY={display}. Start \
         the X server, correct DISPLAY, or run headless under Xvfb: `apt-get install xvfb` \
         then `xvfb-run -s \"-screen 0 1280x800x24\" radiosity view ...` (`radiosity \
         render` makes images without any window)"
    )]
    DisplayUnreachable {
        /// The value of DISPLAY (empty when unset).
        display: String,
    },
    /// The window system or renderer failed.
    #[error("the window could not be opened: {0}. Tried winit (X11) with wgpu; without a GPU install a Vulkan software driver (`apt-get install mesa-vulkan-drivers`) or run with WGPU_BACKEND=gl")]
    Window(String),
    /// The solve or the screenshot failed while the window was open.
    #[error("{0}")]
    Failed(String),
}

/// What eframe's failure to open the window means: no X server at DISPLAY is said in
/// those words (QA of issue #16: it was answered with GPU advice and a path into the
/// cargo registry); otherwise winit's source location ("os error at FILE:LINE: ") is left
/// out of the message.
fn window_error(e: eframe::Error) -> ViewerError {
    let text = e.to_string();
    if text.contains("nor DISPLAY is set") {
        return ViewerError::NoDisplay;
    }
    if text.contains("open connection to X server") {
        return ViewerError::DisplayUnreachable {
            display: std::env::var("DISPLAY").unwrap_or_default(),
        };
    }
    // The message goes before ". Tried winit": no second full stop.
    ViewerError::Window(
        strip_source_location(&text)
            .trim_end_matches('.')
            .to_string(),
    )
}

/// "os error at /path/file.rs:12: message" -> "os error: message".
fn strip_source_location(text: &str) -> String {
    if let Some(rest) = text.find("os error at ").map(|i| &text[i + 12..]) {
        if let Some(colon) = rest.find(": ") {
            let start = text.len() - rest.len() - 12;
            return format!("{}os error: {}", &text[..start], &rest[colon + 2..]);
        }
    }
    text.to_string()
}

/// Opens the window and runs until it is closed; returns notes to print (where the
/// screenshot went).
pub fn run(options: ViewerOptions) -> Result<Vec<String>, ViewerError> {
    // An empty variable is no display either (QA of issue #16: `DISPLAY= view` got winit's
    // "neither WAYLAND_DISPLAY nor DISPLAY is set" with GPU advice).
    let set = |name: &str| std::env::var_os(name).is_some_and(|v| !v.is_empty());
    if cfg!(target_os = "linux") && !set("DISPLAY") && !set("WAYLAND_DISPLAY") {
        return Err(ViewerError::NoDisplay);
    }
    // Fail early, with the adapter search spelled out, when there is no adapter at all.
    gpu::probe_adapter()?;
    let native = eframe::NativeOptions {
        viewport: eframe::egui::ViewportBuilder::default()
            .with_inner_size(options.size)
            .with_title(match &options.path {
                Some(p) => format!("radiosity — {}", p.display()),
                None => "radiosity — Cornell box".into(),
            }),
        // egui-wgpu's default present mode is AutoVsync: double-buffered with vsync.
        renderer: eframe::Renderer::Wgpu,
        ..Default::default()
    };
    let outcome = Arc::new(Mutex::new(app::Outcome::default()));
    let for_app = outcome.clone();
    eframe::run_native(
        "radiosity",
        native,
        Box::new(move |cc| Ok(Box::new(app::ViewerApp::new(cc, options, for_app)))),
    )
    .map_err(window_error)?;
    let outcome = std::mem::take(&mut *outcome.lock().unwrap());
    match outcome.error {
        Some(e) => Err(ViewerError::Failed(e)),
        None => Ok(outcome.notes),
    }
}

#[cfg(test)]
mod window_error_tests {
    use super::*;

    #[test]
    fn winit_source_locations_are_left_out() {
        assert_eq!(
            strip_source_location(
                "winit EventLoopError: os error at /root/.cargo/registry/src/x/winit-0.30.13/\
                 src/platform_impl/linux/mod.rs:788: something failed"
            ),
            "winit EventLoopError: os error: something failed"
        );
        assert_eq!(strip_source_location("no location"), "no location");
    }

    #[test]
    fn no_x_server_names_display_and_xvfb() {
        let text = ViewerError::DisplayUnreachable {
            display: ":99".into(),
        }
        .to_string();
        assert!(
            text.contains("DISPLAY=:99") && text.contains("xvfb-run"),
            "{text}"
        );
        assert!(
            !text.contains("Vulkan") && !text.contains("registry"),
            "{text}"
        );
    }
}
