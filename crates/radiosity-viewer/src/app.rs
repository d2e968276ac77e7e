//! The window: the 3D view (drawn by [`crate::gpu::MeshRenderer`] into a texture that egui
//! shows), the walking controls, and the modeller panel.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, Sender};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use eframe::egui;
use radiosity::mesh::Mesh;
use radiosity::render::{Camera, HoleCover, Shading};
use radiosity::scene::Rgb;
use radiosity::shade::{self, Exposure};
use radiosity::visibility::PolygonBvh;

use crate::camera::{CameraController, MoveKeys};
use crate::gpu::{covered_colours, mesh_bounds, MeshRenderer, Style, Target};
use crate::model::{Modeller, SurfaceColours};
use crate::worker::{self, Recolour, StageProgress, Update};
use crate::ViewerOptions;

/// What the window reports when it closes.
#[derive(Default)]
pub struct Outcome {
    /// A failure to report (the solve failed, the screenshot could not be written).
    pub error: Option<String>,
    /// Lines to print (where the screenshot went).
    pub notes: Vec<String>,
}

/// The GPU side of the view: pipeline, buffers and the texture egui shows.
struct GpuView {
    renderer: MeshRenderer,
    target: Target,
    texture: egui::TextureId,
}

/// The panel's editing state for the selected surface: emission as a colour and a strength.
#[derive(Clone, Copy)]
struct EmissionEdit {
    colour: [f32; 3],
    strength: f64,
    /// The strength slider's upper end, fixed while the surface is selected (a range that
    /// followed the value would run away while dragged).
    top: f64,
}

impl EmissionEdit {
    /// The edit state of emission `e` in `scene`: the slider reaches four times the
    /// brightest emitter of the scene (or of `e`), at least 1.
    fn of(e: Rgb, scene: &radiosity::scene::Scene) -> EmissionEdit {
        let strength = e.max_band();
        let colour = if strength > 0.0 {
            e.0.map(|x| (x / strength) as f32)
        } else {
            [1.0; 3]
        };
        let brightest = scene
            .surfaces
            .iter()
            .map(|s| s.emission.max_band())
            .fold(strength, f64::max);
        EmissionEdit {
            colour,
            strength,
            top: (4.0 * brightest).max(1.0),
        }
    }

    fn rgb(&self) -> Rgb {
        Rgb(self.colour.map(|c| c as f64 * self.strength))
    }
}

pub(crate) struct ViewerApp {
    options: ViewerOptions,
    modeller: Modeller,
    save_path: String,
    edits: Sender<Recolour>,
    updates: Receiver<Update>,
    progress: Arc<StageProgress>,
    outcome: Arc<Mutex<Outcome>>,

    mesh: Option<Arc<Mesh>>,
    bvh: Option<Arc<PolygonBvh>>,
    element_b: Vec<[f64; 3]>,
    /// What covers the holes that dropped buried pieces leave in the mesh's surfaces.
    cover: HoleCover,
    colours_dirty: bool,
    gpu_mesh_pending: bool,
    close_requested: bool,
    solved: bool,
    solve_note: String,
    gpu: Option<GpuView>,

    controller: Option<CameraController>,
    drag_look: bool,
    shading: Shading,
    exposure_stops: f64,
    auto_scale: Option<f64>,
    gamma: f64,
    show_panel: bool,

    selected: Option<usize>,
    emission_edit: Option<EmissionEdit>,
    last_change: Option<(usize, Instant)>,
    edit_seq: u64,
    edit_sent: VecDeque<(u64, Instant)>,
    /// (edit, first picture, converged picture) of the last edit timed, ms.
    edit_timing: (u64, Option<f64>, Option<f64>),
    pending_timing: Option<(u64, Instant, bool)>,

    frame_times: VecDeque<f64>,
    last_frame: Option<Instant>,
    frames_after_solve: u32,
    screenshot_requested: bool,
    status: String,
    started: Instant,
}

impl ViewerApp {
    pub(crate) fn new(
        cc: &eframe::CreationContext<'_>,
        options: ViewerOptions,
        outcome: Arc<Mutex<Outcome>>,
    ) -> ViewerApp {
        let ctx = cc.egui_ctx.clone();
        let wake: Arc<dyn Fn() + Send + Sync> = Arc::new(move || ctx.request_repaint());
        let (edits, updates, progress) = worker::spawn(
            options.scene.clone(),
            options.overrides.apply(options.settings),
            options.solver,
            wake,
        );
        let gpu = cc.wgpu_render_state.as_ref().map(|rs| {
            let renderer = MeshRenderer::new(&rs.device);
            let target = Target::new(&rs.device, 16, 16);
            let texture = rs.renderer.write().register_native_texture(
                &rs.device,
                &target.colour_view,
                wgpu::FilterMode::Nearest,
            );
            GpuView {
                renderer,
                target,
                texture,
            }
        });
        // The window saves in the scene format, never by default over the file opened (a
        // shipped example would be lost to one Ctrl+S): room-edited.scene here.
        let save_path = crate::model::default_save_path(options.path.as_deref())
            .display()
            .to_string();
        let show_panel = options.screenshot.is_none() || options.panel;
        ViewerApp {
            modeller: Modeller::new(options.scene.clone()),
            save_path,
            edits,
            updates,
            progress,
            outcome,
            mesh: None,
            bvh: None,
            element_b: Vec::new(),
            cover: HoleCover::default(),
            colours_dirty: false,
            gpu_mesh_pending: false,
            close_requested: false,
            solved: false,
            solve_note: String::new(),
            gpu,
            controller: None,
            drag_look: false,
            shading: options.shading,
            exposure_stops: 0.0,
            auto_scale: None,
            gamma: 2.2,
            show_panel,
            selected: None,
            emission_edit: None,
            last_change: None,
            edit_seq: 0,
            edit_sent: VecDeque::new(),
            edit_timing: (0, None, None),
            pending_timing: None,
            frame_times: VecDeque::new(),
            last_frame: None,
            frames_after_solve: 0,
            screenshot_requested: false,
            status: String::new(),
            started: Instant::now(),
            options,
        }
    }

    /// Takes in what the worker sent.
    fn receive(&mut self) {
        while let Ok(update) = self.updates.try_recv() {
            match update {
                Update::Mesh(mesh, bvh) => {
                    // Unlit until the first solution: show the emission.
                    let surfaces = &self.modeller.scene.surfaces;
                    self.element_b = mesh
                        .elements
                        .iter()
                        .map(|e| surfaces[e.surface as usize].emission.0)
                        .collect();
                    self.colours_dirty = true;
                    self.cover = HoleCover::new(&self.modeller.scene, &mesh);
                    self.mesh = Some(mesh);
                    self.bvh = Some(bvh);
                    self.gpu_mesh_pending = true;
                    if let (Some(prefix), Some(mesh)) = (&self.options.select, &self.mesh) {
                        self.selected =
                            crate::model::select_by_name(&self.modeller.scene, mesh, prefix);
                        self.emission_edit = self.selected.map(|s| {
                            EmissionEdit::of(
                                self.modeller.colours(s).emission,
                                &self.modeller.scene,
                            )
                        });
                    }
                }
                Update::Solution {
                    element_b,
                    done,
                    note,
                    edit,
                } => {
                    if (edit == 0 && !self.solved) || self.auto_scale.is_none() {
                        if let Some(mesh) = &self.mesh {
                            self.auto_scale =
                                Some(Exposure::Auto.scale(&self.modeller.scene, mesh, &element_b));
                        }
                    }
                    self.element_b = element_b;
                    self.colours_dirty = true;
                    if done {
                        self.solved = true;
                    }
                    self.solve_note = note;
                    if edit > 0 {
                        while self.edit_sent.front().is_some_and(|(k, _)| *k < edit) {
                            self.edit_sent.pop_front();
                        }
                        if let Some(&(k, t)) = self.edit_sent.front() {
                            if k == edit {
                                self.pending_timing = Some((k, t, done));
                                if done {
                                    self.edit_sent.pop_front();
                                }
                            }
                        }
                    }
                }
                Update::Error(message) => {
                    self.status = format!("solve failed: {message}");
                    self.outcome.lock().unwrap().error = Some(self.status.clone());
                    if self.options.screenshot.is_some() {
                        self.close_requested = true;
                    }
                }
            }
        }
    }

    fn exposure_scale(&self) -> f64 {
        self.auto_scale.unwrap_or(1.0) * 2f64.powf(self.exposure_stops)
    }

    /// Sends the current colours to the worker.
    fn send_edit(&mut self) {
        self.edit_seq += 1;
        let colours = self
            .modeller
            .scene
            .surfaces
            .iter()
            .map(|s| (s.reflectance, s.emission))
            .collect();
        let now = Instant::now();
        self.edit_sent.push_back((self.edit_seq, now));
        let _ = self.edits.send(Recolour {
            colours,
            edit: self.edit_seq,
        });
    }

    fn apply_edit(&mut self, s: usize, colours: SurfaceColours) {
        let merge = self
            .last_change
            .is_some_and(|(last, t)| last == s && t.elapsed().as_secs_f64() < 0.75);
        if self.modeller.set(s, colours, merge) {
            self.last_change = Some((s, Instant::now()));
            self.send_edit();
        }
    }

    fn undo(&mut self) {
        if let Some(s) = self.modeller.undo() {
            self.last_change = None;
            if self.selected == Some(s) {
                self.emission_edit = Some(EmissionEdit::of(
                    self.modeller.colours(s).emission,
                    &self.modeller.scene,
                ));
            }
            self.send_edit();
        }
    }

    /// Writes the edited scene with its file's own settings (not the overrides).
    fn save_scene(&mut self) {
        let path = PathBuf::from(self.save_path.trim());
        let settings = self.options.settings;
        // Saving over the file opened is what an editor does: released as an input (every
        // output of the command line is refused over one).
        radiosity::io::release_input(&path);
        self.status =
            match radiosity::scene::write_scene_file(&self.modeller.scene, settings, &path) {
                Ok(()) => {
                    self.modeller.unsaved = 0;
                    format!("saved {}", path.display())
                }
                Err(e) => format!("cannot save {}: {e}", path.display()),
            };
    }

    fn save_view_screenshot(&mut self, frame: &eframe::Frame) {
        let (Some(rs), Some(gpu)) = (frame.wgpu_render_state(), &self.gpu) else {
            return;
        };
        let name = (1..)
            .map(|i| PathBuf::from(format!("radiosity-view-{i:03}.png")))
            .find(|p| !p.exists())
            .expect("a free name");
        self.status = match gpu.target.read_back(&rs.device, &rs.queue) {
            Ok(image) => match image.save(&name) {
                Ok(()) => format!("screenshot saved to {}", name.display()),
                Err(e) => format!("cannot write {}: {e}", name.display()),
            },
            Err(e) => e.to_string(),
        };
    }

    fn keys(&self, ctx: &egui::Context) -> MoveKeys {
        if ctx.text_edit_focused() {
            return MoveKeys::default();
        }
        ctx.input(|i| {
            let down = |a: egui::Key, b: egui::Key| i.key_down(a) || i.key_down(b);
            MoveKeys {
                forward: down(egui::Key::W, egui::Key::ArrowUp),
                back: down(egui::Key::S, egui::Key::ArrowDown),
                left: down(egui::Key::A, egui::Key::ArrowLeft),
                right: down(egui::Key::D, egui::Key::ArrowRight),
                up: down(egui::Key::E, egui::Key::PageUp),
                down: down(egui::Key::Q, egui::Key::PageDown),
            }
        })
    }
}

impl ViewerApp {
    fn panel(&mut self, ui: &mut egui::Ui, frame: &eframe::Frame) {
        ui.heading("Modeller");
        let name = self
            .options
            .path
            .as_ref()
            .map(|p| p.display().to_string())
            .unwrap_or_else(|| "built-in Cornell box".into());
        ui.label(name);
        ui.separator();

        // Solve status
        if self.solved {
            ui.label(&self.solve_note);
        } else {
            let stage = *self.progress.stage.lock().unwrap();
            let done = self.progress.done.load(Ordering::Relaxed);
            let total = self.progress.total.load(Ordering::Relaxed);
            let fraction = if total > 0 {
                (done as f32 / total as f32).min(1.0)
            } else {
                0.0
            };
            ui.add(egui::ProgressBar::new(fraction).text(format!("{stage}...")));
            if !self.solve_note.is_empty() {
                ui.label(&self.solve_note);
            }
        }
        let message = self.progress.message.lock().unwrap().clone();
        if !message.is_empty() {
            ui.small(message);
        }
        ui.separator();

        // View settings
        ui.label("Shading");
        ui.horizontal(|ui| {
            ui.selectable_value(&mut self.shading, Shading::Smooth, "smooth");
            ui.selectable_value(&mut self.shading, Shading::Flat, "flat");
            ui.selectable_value(&mut self.shading, Shading::Wireframe, "wireframe");
        });
        ui.add(egui::Slider::new(&mut self.exposure_stops, -6.0..=6.0).text("exposure (stops)"));
        ui.horizontal(|ui| {
            if ui.button("auto exposure").clicked() {
                if let Some(mesh) = &self.mesh {
                    self.auto_scale =
                        Some(Exposure::Auto.scale(&self.modeller.scene, mesh, &self.element_b));
                    self.exposure_stops = 0.0;
                }
            }
        });
        ui.add(egui::Slider::new(&mut self.gamma, 1.0..=3.5).text("gamma"));
        ui.separator();

        // The selected surface
        match self.selected {
            None => {
                ui.label("Click a surface to edit it.");
            }
            Some(s) => {
                let mut colours = self.modeller.colours(s);
                ui.strong(format!("#{} ({s})", self.modeller.scene.surfaces[s].name));
                let mut rho = colours.reflectance.0.map(|x| x as f32);
                let mut changed = false;
                ui.horizontal(|ui| {
                    ui.label("reflectance");
                    changed |= egui::color_picker::color_edit_button_rgb(ui, &mut rho).changed();
                    ui.label(format!("{:.2} {:.2} {:.2}", rho[0], rho[1], rho[2]));
                });
                let mut em = self
                    .emission_edit
                    .unwrap_or_else(|| EmissionEdit::of(colours.emission, &self.modeller.scene));
                ui.horizontal(|ui| {
                    ui.label("emission");
                    changed |=
                        egui::color_picker::color_edit_button_rgb(ui, &mut em.colour).changed();
                });
                changed |= ui
                    .add(egui::Slider::new(&mut em.strength, 0.0..=em.top).text("strength"))
                    .changed();
                if changed {
                    colours.reflectance = Rgb(rho.map(f64::from));
                    colours.emission = em.rgb();
                    self.emission_edit = Some(em);
                    self.apply_edit(s, colours);
                }
                let (_, first, converged) = self.edit_timing;
                if let Some(first) = first {
                    ui.label(format!(
                        "edit to picture: {first:.0} ms (first sweep), {} (converged)",
                        converged.map_or("...".to_string(), |c| format!("{c:.0} ms"))
                    ));
                }
            }
        }
        ui.separator();
        ui.horizontal(|ui| {
            if ui
                .add_enabled(
                    self.modeller.undo_len() > 0,
                    egui::Button::new("undo (Ctrl+Z)"),
                )
                .clicked()
            {
                self.undo();
            }
            ui.label(format!("{} edits to undo", self.modeller.undo_len()));
        });
        ui.horizontal(|ui| {
            ui.text_edit_singleline(&mut self.save_path);
            if ui.button("save scene").clicked() {
                self.save_scene();
            }
        });
        if ui.button("screenshot (P)").clicked() {
            self.save_view_screenshot(frame);
        }
        if !self.status.is_empty() {
            ui.label(&self.status);
        }
        ui.separator();
        ui.small(
            "W/S or Up/Down: forward/back · A/D or Left/Right: left/right · E/Q or \
             PageUp/PageDown: up/down · drag: look · wheel: speed · click: select · Tab: panel · \
             P or F12: screenshot · Ctrl+Z: undo · Ctrl+S: save",
        );
        if let Some(c) = &self.controller {
            ui.small(format!("speed {:.3} units/s", c.speed));
        }
    }

    fn view(&mut self, ui: &mut egui::Ui, frame: &eframe::Frame) {
        let size = ui.available_size();
        let (rect, response) = ui.allocate_exact_size(size, egui::Sense::click_and_drag());
        let ppp = ui.ctx().pixels_per_point();
        let width = (rect.width() * ppp).round().max(1.0) as u32;
        let height = (rect.height() * ppp).round().max(1.0) as u32;

        // Camera: start where `render`'s default camera is.
        if self.controller.is_none() {
            if let Some(mesh) = &self.mesh {
                let cam = Camera::for_scene(&self.modeller.scene, width, height);
                let (lo, hi) = mesh_bounds(mesh);
                self.controller = Some(CameraController::new(&cam, (hi - lo).length()));
            }
        }
        let now = Instant::now();
        let dt = self
            .last_frame
            .map_or(0.0, |t| (now - t).as_secs_f64())
            .min(0.25);
        self.last_frame = Some(now);
        if dt > 0.0 {
            self.frame_times.push_back(dt);
            if self.frame_times.len() > 60 {
                self.frame_times.pop_front();
            }
        }
        let keys = self.keys(ui.ctx());
        let mut moving = keys.any();
        if let Some(c) = &mut self.controller {
            c.update(keys, dt);
            if response.drag_started() {
                self.drag_look = true;
            }
            if response.dragged() && self.drag_look {
                let d = response.drag_delta();
                c.look(d.x as f64, d.y as f64);
                moving = true;
            }
            if response.hovered() {
                let scroll = ui.ctx().input(|i| i.smooth_scroll_delta.y);
                if scroll != 0.0 {
                    c.scroll(scroll as f64 / 50.0);
                }
            }
        }
        if !response.dragged() {
            self.drag_look = false;
        }
        let camera = self.controller.map(|c| c.camera(width, height));

        // A click or drag in the view takes the keyboard back from the panel's widgets
        // (a slider keeps focus after it is used, and would take the arrow keys).
        if response.clicked() || response.drag_started() {
            ui.memory_mut(|m| {
                if let Some(id) = m.focused() {
                    m.surrender_focus(id);
                }
            });
        }

        // Pick the surface under a click.
        if response.clicked() {
            if let (Some(pos), Some(cam), Some(bvh), Some(mesh)) = (
                response.interact_pointer_pos(),
                &camera,
                &self.bvh,
                &self.mesh,
            ) {
                let x = ((pos.x - rect.min.x) * ppp) as f64;
                let y = ((pos.y - rect.min.y) * ppp) as f64;
                let dir = cam.ray_direction(x, y);
                let (lo, hi) = mesh_bounds(mesh);
                let far = (cam.eye - 0.5 * (lo + hi)).length() + (hi - lo).length();
                let hit = bvh.closest_hit(cam.eye, dir, 0.0, far);
                self.selected = hit.map(|h| mesh.elements[h.id as usize].surface as usize);
                self.emission_edit = self.selected.map(|s| {
                    EmissionEdit::of(self.modeller.colours(s).emission, &self.modeller.scene)
                });
                self.last_change = None;
                if self.selected.is_some() {
                    self.show_panel = true;
                }
            }
        }

        // Draw
        let glow_active = self
            .last_change
            .is_some_and(|(_, t)| t.elapsed().as_secs_f64() < 1.5);
        let glow = if self.selected.is_none() {
            0.0
        } else if glow_active {
            0.6 + 0.4 * (self.started.elapsed().as_secs_f64() * 6.0).sin()
        } else {
            0.25
        };
        let style = Style {
            shading: self.shading,
            exposure_scale: self.exposure_scale(),
            gamma: self.gamma,
            selected: self.selected.map(|s| s as u32),
            glow,
        };
        let mut drew = false;
        if let (Some(rs), Some(gpu)) = (frame.wgpu_render_state(), &mut self.gpu) {
            if gpu.target.width != width || gpu.target.height != height {
                gpu.target = Target::new(&rs.device, width, height);
                rs.renderer.write().update_egui_texture_from_wgpu_texture(
                    &rs.device,
                    &gpu.target.colour_view,
                    wgpu::FilterMode::Nearest,
                    gpu.texture,
                );
            }
            if let Some(mesh) = &self.mesh {
                if self.gpu_mesh_pending {
                    let on_top = crate::gpu::on_top_surfaces(&self.modeller.scene);
                    gpu.renderer
                        .set_mesh_covered(&rs.device, mesh, &on_top, &self.cover);
                    self.gpu_mesh_pending = false;
                    self.colours_dirty = true;
                }
                if self.colours_dirty {
                    let mut vertex_b = shade::vertex_radiosity(mesh, &self.element_b);
                    shade::smooth_objects(&self.modeller.scene, mesh, &mut vertex_b);
                    let colours = covered_colours(mesh, &self.cover, &self.element_b, &vertex_b);
                    gpu.renderer.set_colours(&rs.device, &rs.queue, &colours);
                    self.colours_dirty = false;
                    drew = true;
                }
            }
            if let Some(cam) = &camera {
                let mut encoder = rs.device.create_command_encoder(&Default::default());
                gpu.renderer
                    .draw(&rs.queue, &mut encoder, &gpu.target, cam, &style);
                rs.queue.submit([encoder.finish()]);
            }
            ui.painter().image(
                gpu.texture,
                rect,
                egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0)),
                egui::Color32::WHITE,
            );
        } else {
            ui.painter().text(
                rect.center(),
                egui::Align2::CENTER_CENTER,
                "no wgpu renderer",
                egui::FontId::proportional(20.0),
                egui::Color32::WHITE,
            );
        }
        if drew {
            if let Some((edit, sent, done)) = self.pending_timing.take() {
                let ms = sent.elapsed().as_secs_f64() * 1e3;
                let converged = done.then_some(ms);
                self.edit_timing = match self.edit_timing {
                    // A later picture of the same edit: only the converged time is new.
                    (k, first, _) if k == edit => (k, first, converged),
                    // The first picture of this edit (converged already when the solve
                    // took less than one snapshot interval).
                    _ => (edit, Some(ms), converged),
                };
            }
        }

        // Overlay: frame time and progress
        let mean = if self.frame_times.is_empty() {
            0.0
        } else {
            self.frame_times.iter().sum::<f64>() / self.frame_times.len() as f64
        };
        let mut text = if mean > 0.0 {
            format!("{:.1} ms/frame ({:.0} fps)", mean * 1e3, 1.0 / mean)
        } else {
            "-".to_string()
        };
        if !self.solved {
            let stage = *self.progress.stage.lock().unwrap();
            let done = self.progress.done.load(Ordering::Relaxed);
            let total = self.progress.total.load(Ordering::Relaxed);
            if total > 0 {
                text += &format!("\n{stage} {:.0} %", 100.0 * done as f64 / total as f64);
            } else {
                text += &format!("\n{stage}");
            }
            if !self.solve_note.is_empty() {
                text += &format!("\n{}", self.solve_note);
            }
        }
        ui.painter().text(
            rect.min + egui::vec2(8.0, 6.0),
            egui::Align2::LEFT_TOP,
            text,
            egui::FontId::monospace(13.0),
            egui::Color32::from_rgb(255, 230, 120),
        );
        if moving || glow_active || !self.solved || self.options.screenshot.is_some() {
            ui.ctx().request_repaint();
        }
    }
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        self.receive();
        let ctx = ui.ctx().clone();

        // Keyboard shortcuts
        if !ctx.text_edit_focused() {
            let (tab, shot, undo, save) = ctx.input(|i| {
                (
                    i.key_pressed(egui::Key::Tab),
                    i.key_pressed(egui::Key::P) || i.key_pressed(egui::Key::F12),
                    i.modifiers.command && i.key_pressed(egui::Key::Z),
                    i.modifiers.command && i.key_pressed(egui::Key::S),
                )
            });
            if tab {
                self.show_panel = !self.show_panel;
            }
            if shot {
                self.save_view_screenshot(frame);
            }
            if undo {
                self.undo();
            }
            if save {
                self.save_scene();
            }
        }

        if self.show_panel {
            egui::Panel::right("modeller")
                .default_size(320.0)
                .resizable(true)
                .show(ui, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| self.panel(ui, frame));
                });
        }
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| self.view(ui, frame));

        // --screenshot FILE --frames N: N frames once solved, then the whole window.
        if let Some(path) = self.options.screenshot.clone() {
            if self.solved && self.gpu.is_some() {
                self.frames_after_solve += 1;
            }
            if self.frames_after_solve >= self.options.frames.max(1) && !self.screenshot_requested {
                self.screenshot_requested = true;
                let outcome = self.outcome.clone();
                let ctx2 = ctx.clone();
                ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(
                    egui::ScreenshotCallback::new(move |image| {
                        let [w, h] = image.size;
                        let bytes: Vec<u8> =
                            image.pixels.iter().flat_map(|c| c.to_array()).collect();
                        let mut o = outcome.lock().unwrap();
                        match image::RgbaImage::from_raw(w as u32, h as u32, bytes)
                            .ok_or_else(|| "bad screenshot size".to_string())
                            .and_then(|img| img.save(&path).map_err(|e| e.to_string()))
                        {
                            Ok(()) => o.notes.push(format!(
                                "screenshot ({w} x {h}) saved to {}",
                                path.display()
                            )),
                            Err(e) => {
                                o.error = Some(format!("cannot write {}: {e}", path.display()))
                            }
                        }
                        drop(o);
                        ctx2.send_viewport_cmd(egui::ViewportCommand::Close);
                        ctx2.request_repaint();
                    }),
                ));
            }
        }
        if self.close_requested {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }
}
