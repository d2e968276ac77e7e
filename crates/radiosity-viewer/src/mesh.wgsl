// The one shader of the viewer: the solved mesh, lit by its own radiosities.
//
// Vertex colours are radiosities in the scene's units (linear). The fragment stage does
// what radiosity::shade does on the CPU: multiply by the exposure scale, clamp to [0, 1],
// gamma-correct (paper 2.7: value^(1/gamma)); the target is a plain (non-sRGB) 8-bit
// texture, so the stored bytes are these values times 255, as in the CPU renderer.

struct View {
    view_proj: mat4x4<f32>,
    // Radiosity -> display value factor (before clamping).
    exposure: f32,
    // 1 / gamma.
    inv_gamma: f32,
    // 0 smooth, 1 flat, 2 wireframe.
    mode: u32,
    // Surface index drawn with a glow, or 0xffffffff for none.
    selected: u32,
    // Strength of the glow in [0, 1].
    glow: f32,
    _pad0: f32,
    _pad1: f32,
    _pad2: f32,
};

@group(0) @binding(0) var<uniform> view: View;

struct VertexIn {
    @builtin(vertex_index) index: u32,
    @location(0) position: vec3<f32>,
    // surface index << 5 | hole cover << 4 | lies on another surface << 3 | mask of the
    // triangle's edges that are element edges.
    @location(1) info: u32,
    @location(2) vertex_b: vec3<f32>,
    @location(3) element_b: vec3<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) vertex_b: vec3<f32>,
    @location(1) @interpolate(flat) element_b: vec3<f32>,
    @location(2) bary: vec3<f32>,
    @location(3) @interpolate(flat) info: u32,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = view.view_proj * vec4<f32>(v.position, 1.0);
    if ((v.info & 8u) != 0u) {
        // A surface lying on another (a rug on a floor): drawn as if 1e-5 of its distance
        // nearer (depth is reversed, near/distance), some 100 steps of the f32 depth, so
        // it wins where the two share a plane.
        out.clip.z = out.clip.z * (1.0 + 1e-5);
    }
    if ((v.info & 16u) != 0u) {
        // The hole cover: drawn as if 1e-5 of its distance farther, so that the elements
        // of its own surface, in the same plane, win wherever they are.
        out.clip.z = out.clip.z * (1.0 - 1e-5);
    }
    out.vertex_b = v.vertex_b;
    out.element_b = v.element_b;
    // Draws are not indexed, so vertex k of every triangle has index 3t + k.
    let k = v.index % 3u;
    out.bary = vec3<f32>(f32(k == 0u), f32(k == 1u), f32(k == 2u));
    out.info = v.info;
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // Distance to each edge in pixels (derivatives in uniform control flow).
    let pixels = in.bary / max(fwidth(in.bary), vec3<f32>(1e-6));
    if (!front) {
        // The back of a one-sided surface is black, as in the CPU renderer.
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let mask = in.info & 7u;
    let surface = in.info >> 5u;
    var display: vec3<f32>;
    if (view.mode == 2u) {
        var d = 1e9;
        if ((mask & 1u) != 0u) { d = min(d, pixels.x); }
        if ((mask & 2u) != 0u) { d = min(d, pixels.y); }
        if ((mask & 4u) != 0u) { d = min(d, pixels.z); }
        display = vec3<f32>(select(0.0, 1.0, d < 0.75));
    } else {
        var b = in.vertex_b;
        if (view.mode == 1u) {
            b = in.element_b;
        }
        display = pow(clamp(b * view.exposure, vec3<f32>(0.0), vec3<f32>(1.0)), vec3<f32>(view.inv_gamma));
    }
    if (surface == view.selected) {
        display = mix(display, vec3<f32>(1.0, 0.85, 0.35), 0.35 * view.glow);
    }
    return vec4<f32>(display, 1.0);
}
