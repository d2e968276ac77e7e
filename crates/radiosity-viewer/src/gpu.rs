//! The wgpu renderer of the solved mesh, shared by the window and by offscreen rendering.
//!
//! [`MeshRenderer`] owns the pipeline (one shader, `mesh.wgsl`) and the vertex buffers;
//! [`Target`] is a colour + depth texture pair that can be read back. The window draws into
//! a `Target` every frame and shows it as an egui image; [`render_offscreen`] draws into one
//! with a device of its own and returns the pixels, for tests, screenshots and benchmarks.
//!
//! Triangles are drawn without an index buffer (three vertices per triangle) so that each
//! triangle can carry its element's flat colour and the mask of its edges that are element
//! edges (a quadrilateral element is two triangles, whose shared diagonal is not drawn in
//! wireframe).

use std::fmt;

use bytemuck::{Pod, Zeroable};
use glam::{DMat4, DVec3, DVec4};
use radiosity::mesh::Mesh;
use radiosity::render::{Camera, HoleCover, Shading};
use radiosity::scene::Scene;
use wgpu::util::DeviceExt;

/// The colour format of every [`Target`]: 8 bits per channel, not sRGB (the shader applies
/// the paper's gamma itself, as the CPU renderer does).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Why the GPU could not be used.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No adapter (GPU or software driver) was found.
    #[error(
        "no graphics adapter found (tried wgpu backends: {tried}). Install a Vulkan driver: on \
         Debian/Ubuntu without a GPU, `apt-get install mesa-vulkan-drivers` gives the lavapipe \
         software driver; or try `WGPU_BACKEND=gl` for OpenGL ({source})"
    )]
    NoAdapter {
        /// The backends that were asked for.
        tried: String,
        /// wgpu's reason.
        source: wgpu::RequestAdapterError,
    },
    /// The adapter refused to create a device.
    #[error("the graphics adapter {adapter} could not create a device: {source}")]
    Device {
        /// The adapter's name and backend.
        adapter: String,
        /// wgpu's reason.
        source: wgpu::RequestDeviceError,
    },
    /// Reading pixels back failed.
    #[error("reading the image back from the GPU failed: {0}")]
    Readback(String),
}

/// How the mesh is drawn, besides the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// Smooth (vertex radiosities), flat (element radiosities) or wireframe.
    pub shading: Shading,
    /// Radiosities are multiplied by this before clamping to [0, 1]
    /// (see `radiosity::shade::Exposure::scale`).
    pub exposure_scale: f64,
    /// display = value^(1 / gamma) (paper 2.7).
    pub gamma: f64,
    /// The surface drawn with a highlight, if any.
    pub selected: Option<u32>,
    /// The highlight's strength in [0, 1].
    pub glow: f64,
}

impl Default for Style {
    /// Smooth shading, exposure 1, gamma 2.2, nothing selected.
    fn default() -> Style {
        Style {
            shading: Shading::Smooth,
            exposure_scale: 1.0,
            gamma: 2.2,
            selected: None,
            glow: 0.0,
        }
    }
}

/// The uniform block of `mesh.wgsl` (its `View`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct ViewUniform {
    view_proj: [[f32; 4]; 4],
    exposure: f32,
    inv_gamma: f32,
    mode: u32,
    selected: u32,
    glow: f32,
    pad: [f32; 3],
}

/// Geometry of one vertex: position and `surface << 5 | hole cover << 4 | on top << 3 |
/// edge mask`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct GeometryVertex {
    /// Position, scene units.
    pub position: [f32; 3],
    /// Surface index shifted left by 5; bit 4 set for a triangle of the hole cover (drawn a
    /// little away from the eye, see [`cover_geometry`]); bit 3 set for a surface that lies
    /// on another (drawn a little towards the eye, see [`on_top_surfaces`]); bits 0-2 the
    /// mask of the triangle's element edges (bit k: the edge opposite the triangle's vertex
    /// k).
    pub info: u32,
}

/// Colours of one vertex: its vertex radiosity (smooth shading) and its element's
/// radiosity (flat shading), linear, in the scene's units.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct ColourVertex {
    /// The interpolated (vertex) radiosity.
    pub vertex_b: [f32; 3],
    /// The element's radiosity.
    pub element_b: [f32; 3],
}

/// For every triangle the mesh is drawn with, its element index. The triangles are those of
/// the elements' display polygons ([`Mesh::display`]): a quadrilateral element is two
/// triangles, (0, 1, 2) and (0, 2, 3), and an element with T-vertices on its edges (next to
/// smaller elements) is cut so that its triangles use them, which leaves no cracks.
pub fn triangle_elements(mesh: &Mesh) -> Vec<u32> {
    let display = mesh.display();
    let mut out = Vec::with_capacity(display.all_triangles().len());
    for e in 0..mesh.len() {
        out.extend(std::iter::repeat_n(e as u32, display.triangles(e).len()));
    }
    out
}

/// The triangles of `mesh` as vertices, three per triangle, in [`triangle_elements`] order.
/// `on_top` flags, per surface, those that lie on another ([`on_top_surfaces`]; may be
/// empty: none).
pub fn geometry_vertices(mesh: &Mesh, on_top: &[bool]) -> Vec<GeometryVertex> {
    let display = mesh.display();
    let mut out = Vec::with_capacity(3 * display.all_triangles().len());
    for (e, el) in mesh.elements.iter().enumerate() {
        let top = on_top.get(el.surface as usize).copied().unwrap_or(false);
        let surface = el.surface << SURFACE_SHIFT | (top as u32) << 3;
        for t in display.triangles(e) {
            // The mask of element edges: bit k = the edge opposite vertex k.
            for &v in &t.vertices {
                out.push(GeometryVertex {
                    position: mesh.vertices[v as usize].as_vec3().to_array(),
                    info: surface | t.outline as u32,
                });
            }
        }
    }
    out
}

/// Where the surface index starts in [`GeometryVertex::info`].
const SURFACE_SHIFT: u32 = 5;

/// The triangles of the hole cover ([`HoleCover`]: the holes that dropped buried pieces
/// leave in the surfaces, which the CPU renderer covers ray by ray) as vertices, three per
/// triangle, flagged so that the shader draws them a little behind the elements: they show
/// only where no element covers the surface. No edges of theirs are element edges.
pub fn cover_geometry(cover: &HoleCover) -> Vec<GeometryVertex> {
    cover
        .corners
        .chunks(3)
        .zip(&cover.surfaces)
        .flat_map(|(t, &s)| {
            t.iter().map(move |p| GeometryVertex {
                position: p.as_vec3().to_array(),
                info: s << SURFACE_SHIFT | 1 << 4,
            })
        })
        .collect()
}

/// The colours matching [`cover_geometry`], for `mesh` with radiosities `element_b` (per
/// element) and `vertex_b` (per vertex; may be empty) as for [`colour_vertices`].
pub fn cover_colours(
    cover: &HoleCover,
    mesh: &Mesh,
    element_b: &[[f64; 3]],
    vertex_b: &[[f64; 3]],
) -> Vec<ColourVertex> {
    let f = |b: [f64; 3]| b.map(|x| x as f32);
    cover
        .radiosity(mesh, element_b, vertex_b)
        .into_iter()
        .map(|(smooth, flat)| ColourVertex {
            vertex_b: f(smooth),
            element_b: f(flat),
        })
        .collect()
}

/// The colours of everything [`MeshRenderer::set_mesh_covered`] uploads: [`colour_vertices`]
/// followed by [`cover_colours`].
pub fn covered_colours(
    mesh: &Mesh,
    cover: &HoleCover,
    element_b: &[[f64; 3]],
    vertex_b: &[[f64; 3]],
) -> Vec<ColourVertex> {
    let mut colours = colour_vertices(mesh, element_b, vertex_b);
    colours.extend(cover_colours(cover, mesh, element_b, vertex_b));
    colours
}

/// The colours matching [`geometry_vertices`]: `vertex_b` per mesh vertex (may be empty,
/// then the element's radiosity is used for smooth shading too) and `element_b` per element.
pub fn colour_vertices(
    mesh: &Mesh,
    element_b: &[[f64; 3]],
    vertex_b: &[[f64; 3]],
) -> Vec<ColourVertex> {
    let display = mesh.display();
    let mut out = Vec::with_capacity(3 * display.all_triangles().len());
    let f = |b: [f64; 3]| b.map(|x| x as f32);
    for (e, &b) in element_b.iter().enumerate().take(mesh.len()) {
        let eb = f(b);
        for t in display.triangles(e) {
            for &v in &t.vertices {
                let vb = vertex_b.get(v as usize).map_or(eb, |&b| f(b));
                out.push(ColourVertex {
                    vertex_b: vb,
                    element_b: eb,
                });
            }
        }
    }
    out
}

/// Per surface of `scene`, true when it lies on another ([`radiosity::scene::lying_on`]: a
/// rug in or just above a floor). The shader draws these a hundred-thousandth of their
/// distance nearer the eye, so that where a depth buffer cannot separate them from the
/// surface below (in its plane, or the pieces straddling their outline that contact
/// refinement keeps) they win, instead of flickering through it.
pub fn on_top_surfaces(scene: &Scene) -> Vec<bool> {
    let mut on_top = vec![false; scene.surfaces.len()];
    let bvh = radiosity::visibility::PolygonBvh::over_surfaces(scene);
    for o in radiosity::scene::lying_on(scene, &bvh) {
        on_top[o.upper as usize] = true;
    }
    on_top
}

/// The view-projection matrix of `camera` (wgpu clip space: depth in [0, 1]) for a scene
/// with bounding box `bounds`: the near and far planes enclose the box as seen from the eye.
/// Depth is reversed, 1 at the near plane and 0 at the far one, so that with a float depth
/// buffer its precision is relative (some 1e-7 of the distance) at every distance: with depth
/// 0 at the near plane, a rug 5 mm above a floor 5 m away was within one step of it and
/// flickered through.
pub fn view_projection(camera: &Camera, bounds: (DVec3, DVec3)) -> DMat4 {
    let (lo, hi) = bounds;
    let (forward, _, up) = camera.basis();
    let up = up.normalize();
    let diag = if lo.is_finite() && hi.is_finite() {
        (hi - lo).length()
    } else {
        1.0
    };
    let centre = if lo.is_finite() && hi.is_finite() {
        0.5 * (lo + hi)
    } else {
        camera.eye
    };
    let far = ((camera.eye - centre).length() + diag).max(1e-6) * 1.01;
    let near = far * 1e-5;
    let aspect = camera.width.max(1) as f64 / camera.height.max(1) as f64;
    // View: right-handed, looking down -z (right = forward x up, as the CPU camera).
    let right = forward.cross(up);
    let e = camera.eye;
    let view = DMat4::from_cols(
        DVec4::new(right.x, up.x, -forward.x, 0.0),
        DVec4::new(right.y, up.y, -forward.y, 0.0),
        DVec4::new(right.z, up.z, -forward.z, 0.0),
        DVec4::new(-right.dot(e), -up.dot(e), forward.dot(e), 1.0),
    );
    // Perspective with depth 1 at `near` and 0 at `far` (reversed, in wgpu's clip space).
    let h = 1.0 / (0.5 * camera.fov_y_degrees.to_radians()).tan();
    let proj = DMat4::from_cols(
        DVec4::new(h / aspect, 0.0, 0.0, 0.0),
        DVec4::new(0.0, h, 0.0, 0.0),
        DVec4::new(0.0, 0.0, near / (far - near), -1.0),
        DVec4::new(0.0, 0.0, near * far / (far - near), 0.0),
    );
    proj * view
}

/// The bounding box (min, max) of a mesh's vertices.
pub fn mesh_bounds(mesh: &Mesh) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for v in &mesh.vertices {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    (lo, hi)
}

/// A colour texture ([`COLOR_FORMAT`]) and its depth buffer, `width` x `height`.
pub struct Target {
    /// The colour texture (render attachment, texture binding, copy source).
    pub colour: wgpu::Texture,
    /// A view of it.
    pub colour_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl Target {
    /// A target of the given size (at least 1 x 1).
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Target {
        let (width, height) = (width.max(1), height.max(1));
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |format, usage, label| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let colour = texture(
            COLOR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            "radiosity colour",
        );
        let depth = texture(
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
            "radiosity depth",
        );
        Target {
            colour_view: colour.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            colour,
            width,
            height,
        }
    }

    /// Copies the colour texture back to the CPU (waits for the GPU).
    pub fn read_back(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<image::RgbaImage, GpuError> {
        let row = 4 * self.width;
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let padded = row.div_ceil(align) * align;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("radiosity readback"),
            size: padded as u64 * self.height as u64,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &self.colour,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded),
                    rows_per_image: Some(self.height),
                },
            },
            wgpu::Extent3d {
                width: self.width,
                height: self.height,
                depth_or_array_layers: 1,
            },
        );
        queue.submit([encoder.finish()]);
        let slice = buffer.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        rx.recv()
            .map_err(|e| GpuError::Readback(e.to_string()))?
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        let data = slice
            .get_mapped_range()
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        let mut pixels = Vec::with_capacity((row * self.height) as usize);
        for y in 0..self.height as usize {
            let start = y * padded as usize;
            pixels.extend_from_slice(&data[start..start + row as usize]);
        }
        drop(data);
        buffer.unmap();
        image::RgbaImage::from_raw(self.width, self.height, pixels)
            .ok_or_else(|| GpuError::Readback("image size mismatch".into()))
    }
}

/// The pipeline and the mesh's vertex buffers.
pub struct MeshRenderer {
    pipeline: wgpu::RenderPipeline,
    uniform: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    geometry: Option<wgpu::Buffer>,
    colours: Option<wgpu::Buffer>,
    vertex_count: u32,
    bounds: (DVec3, DVec3),
}

impl MeshRenderer {
    /// Builds the pipeline for [`COLOR_FORMAT`] targets.
    pub fn new(device: &wgpu::Device) -> MeshRenderer {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("mesh.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("mesh.wgsl").into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("radiosity view"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("radiosity view"),
            size: std::mem::size_of::<ViewUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("radiosity view"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("radiosity mesh"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let geometry_layout = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<GeometryVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Uint32],
        };
        let colour_layout = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<ColourVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![2 => Float32x3, 3 => Float32x3],
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("radiosity mesh"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(geometry_layout), Some(colour_layout)],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                // Backs are drawn (black) so that they hide what is behind them, as in the
                // CPU renderer.
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                // Reversed depth (see `view_projection`): nearer is greater.
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: COLOR_FORMAT,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        MeshRenderer {
            pipeline,
            uniform,
            bind_group,
            geometry: None,
            colours: None,
            vertex_count: 0,
            bounds: (DVec3::ZERO, DVec3::ONE),
        }
    }

    /// Uploads the mesh's triangles (once per mesh); `on_top` as for [`geometry_vertices`].
    pub fn set_mesh(&mut self, device: &wgpu::Device, mesh: &Mesh, on_top: &[bool]) {
        self.set_mesh_covered(device, mesh, on_top, &HoleCover::default());
    }

    /// [`MeshRenderer::set_mesh`] followed by the triangles of `cover` (the mesh's hole
    /// cover, [`cover_geometry`]); the colours then are [`covered_colours`].
    pub fn set_mesh_covered(
        &mut self,
        device: &wgpu::Device,
        mesh: &Mesh,
        on_top: &[bool],
        cover: &HoleCover,
    ) {
        let mut vertices = geometry_vertices(mesh, on_top);
        vertices.extend(cover_geometry(cover));
        self.set_triangles(device, &vertices, mesh_bounds(mesh));
    }

    /// Uploads triangles given as vertices (three per triangle; see [`geometry_vertices`])
    /// whose bounding box is `bounds`.
    pub fn set_triangles(
        &mut self,
        device: &wgpu::Device,
        vertices: &[GeometryVertex],
        bounds: (DVec3, DVec3),
    ) {
        self.vertex_count = vertices.len() as u32;
        self.bounds = bounds;
        self.geometry = (!vertices.is_empty()).then(|| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("radiosity geometry"),
                contents: bytemuck::cast_slice(vertices),
                usage: wgpu::BufferUsages::VERTEX,
            })
        });
        self.colours = None;
    }

    /// Uploads new radiosities ([`colour_vertices`] of the mesh given to `set_mesh`).
    pub fn set_colours(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        colours: &[ColourVertex],
    ) {
        if colours.len() as u32 != self.vertex_count || colours.is_empty() {
            self.colours = None;
            return;
        }
        let bytes: &[u8] = bytemuck::cast_slice(colours);
        match &self.colours {
            Some(buffer) if buffer.size() == bytes.len() as u64 => {
                queue.write_buffer(buffer, 0, bytes)
            }
            _ => {
                self.colours = Some(
                    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("radiosity colours"),
                        contents: bytes,
                        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                    }),
                )
            }
        }
    }

    /// Records the drawing of the mesh from `camera` into `target` (cleared to black).
    pub fn draw(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        target: &Target,
        camera: &Camera,
        style: &Style,
    ) {
        let uniform = ViewUniform {
            view_proj: view_projection(camera, self.bounds)
                .as_mat4()
                .to_cols_array_2d(),
            exposure: style.exposure_scale as f32,
            inv_gamma: if style.gamma.is_finite() && style.gamma > 0.0 {
                (1.0 / style.gamma) as f32
            } else {
                1.0
            },
            mode: match style.shading {
                Shading::Smooth => 0,
                Shading::Flat => 1,
                Shading::Wireframe => 2,
            },
            selected: style.selected.unwrap_or(u32::MAX),
            glow: style.glow as f32,
            pad: [0.0; 3],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("radiosity mesh"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &target.colour_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &target.depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        if let (Some(geometry), Some(colours)) = (&self.geometry, &self.colours) {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.set_vertex_buffer(0, geometry.slice(..));
            pass.set_vertex_buffer(1, colours.slice(..));
            pass.draw(0..self.vertex_count, 0..1);
        }
    }
}

/// A device of our own, without a window.
pub struct Headless {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// The adapter's description.
    pub adapter: AdapterSummary,
}

/// Which adapter is in use, for messages and benchmark records.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AdapterSummary {
    /// The adapter's name (for lavapipe: "llvmpipe (LLVM ...)").
    pub name: String,
    /// Vulkan, Gl, ...
    pub backend: String,
    /// Cpu for software drivers, DiscreteGpu, ...
    pub device_type: String,
}

impl fmt::Display for AdapterSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({}, {})", self.name, self.backend, self.device_type)
    }
}

impl AdapterSummary {
    /// From wgpu's adapter information.
    pub fn new(info: &wgpu::AdapterInfo) -> AdapterSummary {
        AdapterSummary {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
        }
    }
}

/// Looks for an adapter the way the window will (the backends allowed by `WGPU_BACKEND`),
/// without creating a device.
pub fn probe_adapter() -> Result<AdapterSummary, GpuError> {
    let descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
    let tried = format!("{:?}", descriptor.backends);
    let instance = wgpu::Instance::new(descriptor);
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        ..Default::default()
    }))
    .map_err(|source| GpuError::NoAdapter { tried, source })?;
    Ok(AdapterSummary::new(&adapter.get_info()))
}

impl Headless {
    /// The first adapter wgpu offers on the backends allowed by `WGPU_BACKEND` (all by
    /// default), preferring a real GPU, and a device on it.
    pub fn new() -> Result<Headless, GpuError> {
        let descriptor = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        let tried = format!("{:?}", descriptor.backends);
        let instance = wgpu::Instance::new(descriptor);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|source| GpuError::NoAdapter { tried, source })?;
        let summary = AdapterSummary::new(&adapter.get_info());
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("radiosity offscreen"),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|source| GpuError::Device {
            adapter: summary.to_string(),
            source,
        })?;
        Ok(Headless {
            device,
            queue,
            adapter: summary,
        })
    }
}

/// Renders `mesh` with radiosities `element_b` (per element) and `vertex_b` (per vertex)
/// from `camera` on a device of its own (see [`Headless::new`]), `camera.width` x
/// `camera.height` pixels, through the same pipeline as the window.
pub fn render_offscreen(
    mesh: &Mesh,
    element_b: &[[f64; 3]],
    vertex_b: &[[f64; 3]],
    camera: &Camera,
    style: &Style,
) -> Result<(image::RgbaImage, AdapterSummary), GpuError> {
    let gpu = Headless::new()?;
    let image = gpu.render(mesh, element_b, vertex_b, camera, style)?;
    Ok((image, gpu.adapter))
}

impl Headless {
    /// [`render_offscreen`] on this device.
    pub fn render(
        &self,
        mesh: &Mesh,
        element_b: &[[f64; 3]],
        vertex_b: &[[f64; 3]],
        camera: &Camera,
        style: &Style,
    ) -> Result<image::RgbaImage, GpuError> {
        self.render_with_on_top(mesh, &[], element_b, vertex_b, camera, style)
    }

    /// [`Headless::render`] with the surfaces flagged in `on_top` drawn as lying on others
    /// (see [`geometry_vertices`]).
    pub fn render_with_on_top(
        &self,
        mesh: &Mesh,
        on_top: &[bool],
        element_b: &[[f64; 3]],
        vertex_b: &[[f64; 3]],
        camera: &Camera,
        style: &Style,
    ) -> Result<image::RgbaImage, GpuError> {
        let cover = HoleCover::default();
        self.render_covered(mesh, on_top, &cover, element_b, vertex_b, camera, style)
    }

    /// [`Headless::render`] of `mesh`, cut from `scene`, as the window draws it: the
    /// surfaces lying on others drawn on top ([`on_top_surfaces`]) and the holes that
    /// dropped buried pieces leave covered ([`HoleCover`]).
    pub fn render_scene(
        &self,
        scene: &Scene,
        mesh: &Mesh,
        element_b: &[[f64; 3]],
        vertex_b: &[[f64; 3]],
        camera: &Camera,
        style: &Style,
    ) -> Result<image::RgbaImage, GpuError> {
        let (on_top, cover) = (on_top_surfaces(scene), HoleCover::new(scene, mesh));
        self.render_covered(mesh, &on_top, &cover, element_b, vertex_b, camera, style)
    }

    #[allow(clippy::too_many_arguments)]
    fn render_covered(
        &self,
        mesh: &Mesh,
        on_top: &[bool],
        cover: &HoleCover,
        element_b: &[[f64; 3]],
        vertex_b: &[[f64; 3]],
        camera: &Camera,
        style: &Style,
    ) -> Result<image::RgbaImage, GpuError> {
        let mut renderer = MeshRenderer::new(&self.device);
        renderer.set_mesh_covered(&self.device, mesh, on_top, cover);
        let colours = covered_colours(mesh, cover, element_b, vertex_b);
        renderer.set_colours(&self.device, &self.queue, &colours);
        let target = Target::new(&self.device, camera.width, camera.height);
        let mut encoder = self.device.create_command_encoder(&Default::default());
        renderer.draw(&self.queue, &mut encoder, &target, camera, style);
        self.queue.submit([encoder.finish()]);
        target.read_back(&self.device, &self.queue)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity::scene::cornell_box;

    #[test]
    fn refined_room_has_no_t_junctions_in_its_triangles() {
        // The room's floor is split round the furniture three levels deep next to whole
        // elements. No triangle the viewer draws may have a vertex of its own surface inside
        // one of its edges (a T-junction: the rasteriser leaves pinholes along such an
        // edge). Checked by brute force over every edge and vertex of each surface.
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/room.scene");
        let file = radiosity::io::scene_file::read_scene(&path).unwrap();
        let grid = radiosity::mesh::mesh_scene(&file.scene, file.settings.max_patch_area).unwrap();
        let bvh = radiosity::visibility::PolygonBvh::over_surfaces(&file.scene);
        let (mesh, report) = radiosity::mesh::refine_contacts(&grid, &file.scene, &bvh);
        assert!(report.split > 0, "{report:?}");
        let v = geometry_vertices(&mesh, &[]);
        assert_eq!(v.len(), 3 * triangle_elements(&mesh).len());
        let mut checked = 0;
        for s in 0..file.scene.surfaces.len() {
            let points: Vec<glam::Vec3> = mesh.surface_vertices[s]
                .clone()
                .map(|i| mesh.vertices[i as usize].as_vec3())
                .collect();
            for t in v
                .chunks_exact(3)
                .filter(|t| (t[0].info >> SURFACE_SHIFT) as usize == s)
            {
                for k in 0..3 {
                    let a = glam::Vec3::from(t[k].position);
                    let b = glam::Vec3::from(t[(k + 1) % 3].position);
                    let ab = b - a;
                    for &p in &points {
                        let u = (p - a).dot(ab) / ab.length_squared();
                        // Strictly inside the edge, within f32 rounding of it (positions
                        // of a few metres: 1e-6 m is ten times their rounding).
                        if u > 1e-4 && u < 1.0 - 1e-4 {
                            let off = (p - (a + u * ab)).length();
                            assert!(off > 1e-6, "surface {s}: {p} lies on the edge {a} - {b}");
                        }
                    }
                    checked += 1;
                }
            }
        }
        assert!(checked > 1000, "{checked}");
    }

    #[test]
    fn quads_are_two_triangles_without_the_diagonal_in_wireframe() {
        let file = cornell_box();
        let mesh = radiosity::mesh::mesh_scene(&file.scene, file.settings.max_patch_area).unwrap();
        let v = geometry_vertices(&mesh, &[]);
        assert_eq!(v.len(), 3 * triangle_elements(&mesh).len());
        let quads = mesh.elements.iter().filter(|e| e.is_quad()).count();
        assert_eq!(v.len(), 3 * (mesh.len() + quads));
        let c = colour_vertices(&mesh, &vec![[1.0; 3]; mesh.len()], &[]);
        assert_eq!(c.len(), v.len());
    }

    #[test]
    fn depth_separates_a_rug_5_mm_above_a_floor_5_m_away() {
        // The room's case: eye 5 m from a floor, a rug 5 mm nearer, a scene 10 m across.
        // In f32, as the shader computes it, the two depths must differ by many steps of the
        // depth buffer's float (here at least 100 ulps), and the nearer must be greater.
        let cam = Camera {
            eye: DVec3::ZERO,
            look_at: DVec3::new(0.0, 0.0, -1.0),
            up: DVec3::Y,
            fov_y_degrees: 60.0,
            width: 64,
            height: 64,
        };
        let m = view_projection(&cam, (DVec3::splat(-5.0), DVec3::splat(5.0))).as_mat4();
        let depth = |d: f32| {
            let c = m * glam::Vec4::new(0.0, 0.0, -d, 1.0);
            c.z / c.w
        };
        let (floor, rug) = (depth(5.0), depth(4.995));
        assert!(rug > floor, "{rug} {floor}");
        let ulps = rug.to_bits() as i64 - floor.to_bits() as i64;
        assert!(ulps >= 100, "{ulps} steps between {rug} and {floor}");
    }

    #[test]
    fn projection_puts_the_look_at_point_in_the_centre() {
        let cam = Camera {
            eye: DVec3::new(1.0, 2.0, 3.0),
            look_at: DVec3::new(4.0, 2.0, 7.0),
            up: DVec3::Y,
            fov_y_degrees: 50.0,
            width: 64,
            height: 48,
        };
        let m = view_projection(&cam, (DVec3::ZERO, DVec3::splat(10.0)));
        let p = m * cam.look_at.extend(1.0);
        assert!((p.x / p.w).abs() < 1e-9 && (p.y / p.w).abs() < 1e-9, "{p}");
        assert!(p.z / p.w > 0.0 && p.z / p.w < 1.0);
        // A point up and to the right lands where the CPU camera projects it.
        let q = DVec3::new(4.5, 3.0, 6.5);
        let (px, py) = cam.project(q).unwrap();
        let c = m * q.extend(1.0);
        let (sx, sy) = (c.x / c.w, c.y / c.w);
        let (gx, gy) = (0.5 * (sx + 1.0) * 64.0, 0.5 * (1.0 - sy) * 48.0);
        assert!(
            (gx - px).abs() < 1e-6 && (gy - py).abs() < 1e-6,
            "{gx},{gy} vs {px},{py}"
        );
    }
}
