//! A path-traced view ([`PathTraced`]) as an OpenEXR file, so that an expensive reference
//! (thousands of paths a pixel) is traced once and compared with many radiosity renders.
//!
//! One scan-line layer, ZIP-compressed (lossless), every channel 32-bit float, pixels row
//! by row from the top-left corner:
//!
//! | channel | content |
//! | --- | --- |
//! | `R`, `G`, `B` | the pixel's mean radiosity B = pi L per band, in the scene's units |
//! | `se.R`, `se.G`, `se.B` | the standard error of that mean, per band |
//! | `se.Y` | the standard error of the mean luminance |
//! | `emitter` | 1 where a path's first hit was the front of an emitter, else 0 |
//!
//! so any OpenEXR viewer shows the linear image. Custom layer attributes hold what the
//! view is of and how it was traced, exactly (doubles, 32-bit integers and decimal text):
//! the camera (`radiosity.eye.x` ... `radiosity.fovY`, the size being the data window's),
//! the settings (`radiosity.samplesPerPixel`, `radiosity.maxBounces`,
//! `radiosity.rouletteAfter`, `radiosity.nextEvent`, `radiosity.seed`) and the scene's
//! fingerprint (`radiosity.scene`, [`scene_fingerprint`]). The reader refuses a file whose
//! size, camera or scene differs from what it is asked for, naming the file and both
//! values, so a stale reference is never compared with another view.
//!
//! The values are rounded to 32 bits (7 significant digits) when written: far below the
//! noise of any path-traced estimate. The format is the `exr` crate's (BSD-3-Clause, pure
//! Rust), used directly rather than through `image`'s EXR support, which writes only RGB
//! or RGBA and no attributes.

use std::collections::HashMap;
use std::hash::Hasher;
use std::io;
use std::path::{Path, PathBuf};

use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, Layer, LayerAttributes,
    ReadChannels, ReadLayers, Text,
};
use thiserror::Error;

use crate::light::Rgb;
use crate::pathtrace::{PathTraceSettings, PathTraced};
use crate::render::{Camera, Film, FilmContent};
use crate::scene::Scene;

/// A path-traced view read back from a file, with what it was traced from.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedView {
    /// The view (means, standard errors, emitter mask), its values rounded to 32 bits.
    pub view: PathTraced,
    /// The camera it was traced with (equal to the one asked for).
    pub camera: Camera,
    /// The settings it was traced with.
    pub settings: PathTraceSettings,
}

/// Why a path-traced view could not be written or read.
#[derive(Debug, Error)]
pub enum PathTracedFileError {
    /// The file could not be written, opened or read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        source: io::Error,
    },
    /// The file is not an OpenEXR image this program can read (or is damaged).
    #[error("{path} is not a readable OpenEXR file: {message}")]
    NotExr {
        /// The file.
        path: PathBuf,
        /// What the OpenEXR reader said.
        message: String,
    },
    /// An OpenEXR image without a channel or attribute this format needs: not a saved
    /// path-traced view.
    #[error("{path} is an OpenEXR image but not a saved path-traced view: it has no {what}")]
    NotPathTraced {
        /// The file.
        path: PathBuf,
        /// The channel or attribute missing, e.g. "channel se.Y".
        what: String,
    },
    /// The file's image has another size than asked for.
    #[error(
        "{path} holds a {} x {} view, not the {} x {} asked for",
        found.0, found.1, expected.0, expected.1
    )]
    Size {
        /// The file.
        path: PathBuf,
        /// Its width and height.
        found: (usize, usize),
        /// The width and height asked for.
        expected: (usize, usize),
    },
    /// The file was traced from another camera.
    #[error(
        "{path} was traced from another camera: {}, not {}",
        describe_camera(found),
        describe_camera(expected)
    )]
    Camera {
        /// The file.
        path: PathBuf,
        /// The camera in the file.
        found: Box<Camera>,
        /// The camera asked for.
        expected: Box<Camera>,
    },
    /// The file was traced from another scene (other surfaces, corners or colours).
    #[error(
        "{path} was traced from another scene (fingerprint {found:016x}, this scene is \
         {expected:016x})"
    )]
    Scene {
        /// The file.
        path: PathBuf,
        /// The fingerprint in the file.
        found: u64,
        /// The fingerprint of the scene asked for.
        expected: u64,
    },
    /// A stored number is out of range (a negative or non-finite value, a count that is
    /// not positive).
    #[error("{path} is damaged: {what}")]
    BadValue {
        /// The file.
        path: PathBuf,
        /// Which value, and what it is.
        what: String,
    },
}

/// "eye [x, y, z], look-at [...], up [...], vertical field of view F degrees".
fn describe_camera(c: &Camera) -> String {
    // Six significant digits: the floats' last digits are noise to a reader (QA of issue
    // #16: "1.4597499999999999"); the command line's hint gives the exact flags.
    let n = |x: f64| {
        if x == 0.0 {
            "0".to_string()
        } else {
            let digits = (5 - x.abs().log10().floor() as i32).clamp(0, 12) as usize;
            let t = format!("{x:.digits$}");
            if t.contains('.') {
                t.trim_end_matches('0').trim_end_matches('.').to_string()
            } else {
                t
            }
        }
    };
    let v = |v: glam::DVec3| format!("[{}, {}, {}]", n(v.x), n(v.y), n(v.z));
    format!(
        "eye {}, look-at {}, up {}, vertical field of view {} degrees",
        v(c.eye),
        v(c.look_at),
        v(c.up),
        n(c.fov_y_degrees)
    )
}

/// A hash (FNV-1a, 64 bits) of everything a path-traced view of `scene` depends on: every
/// surface's corners, emission and reflectance, bit for bit, in order. Meshing settings do
/// not enter (the path tracer traces the input polygons).
pub fn scene_fingerprint(scene: &Scene) -> u64 {
    let mut h = fnv::FnvHasher::default();
    h.write(&(scene.surfaces.len() as u64).to_le_bytes());
    for s in &scene.surfaces {
        h.write(&(s.vertices.len() as u64).to_le_bytes());
        let values = s
            .vertices
            .iter()
            .flat_map(|v| v.to_array())
            .chain(s.emission.0)
            .chain(s.reflectance.0);
        for x in values {
            h.write(&x.to_bits().to_le_bytes());
        }
    }
    h.finish()
}

const SE_Y: &str = "se.Y";
const EMITTER: &str = "emitter";
const BANDS: [&str; 3] = ["R", "G", "B"];
const SE_BANDS: [&str; 3] = ["se.R", "se.G", "se.B"];

/// The camera's doubles, by attribute name.
pub(crate) fn camera_attributes(c: &Camera) -> [(&'static str, f64); 10] {
    [
        ("radiosity.eye.x", c.eye.x),
        ("radiosity.eye.y", c.eye.y),
        ("radiosity.eye.z", c.eye.z),
        ("radiosity.lookAt.x", c.look_at.x),
        ("radiosity.lookAt.y", c.look_at.y),
        ("radiosity.lookAt.z", c.look_at.z),
        ("radiosity.up.x", c.up.x),
        ("radiosity.up.y", c.up.y),
        ("radiosity.up.z", c.up.z),
        ("radiosity.fovY", c.fov_y_degrees),
    ]
}

const SAMPLES: &str = "radiosity.samplesPerPixel";
const MAX_BOUNCES: &str = "radiosity.maxBounces";
const ROULETTE: &str = "radiosity.rouletteAfter";
const NEXT_EVENT: &str = "radiosity.nextEvent";
const SEED: &str = "radiosity.seed";
const SCENE: &str = "radiosity.scene";

/// Writes `view`, traced from `scene` with `camera` and `settings`, as an OpenEXR file at
/// `path`, atomically (see [`crate::io::write_atomically`]).
///
/// # Panics
/// If the view's size is not the camera's.
pub fn write_path_traced(
    path: &Path,
    view: &PathTraced,
    camera: &Camera,
    settings: &PathTraceSettings,
    scene: &Scene,
) -> Result<(), PathTracedFileError> {
    let (w, h) = (view.width(), view.height());
    assert_eq!(
        (w, h),
        (camera.width as usize, camera.height as usize),
        "the view has the camera's size"
    );
    let film = view.film();
    let pixels: Vec<Rgb> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| Rgb(film.pixel(x, y)[0]))
        .collect();
    let f32s = |f: &dyn Fn(usize) -> f64| (0..w * h).map(|i| f(i) as f32).collect::<Vec<_>>();
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
    for k in 0..3 {
        channels.push(AnyChannel::new(
            BANDS[k],
            FlatSamples::F32(f32s(&|i| pixels[i][k])),
        ));
        channels.push(AnyChannel::new(
            SE_BANDS[k],
            FlatSamples::F32(f32s(&|i| view.standard_errors()[i][k])),
        ));
    }
    channels.push(AnyChannel::new(
        SE_Y,
        FlatSamples::F32(f32s(&|i| view.luminance_standard_errors()[i])),
    ));
    channels.push(AnyChannel::new(
        EMITTER,
        FlatSamples::F32(f32s(&|i| {
            if view.emitter_mask()[i] {
                1.0
            } else {
                0.0
            }
        })),
    ));
    let mut attributes = LayerAttributes::named("path traced");
    attributes.software_name = Some(Text::from("radiosity pathtrace"));
    let mut other: HashMap<Text, AttributeValue> = camera_attributes(camera)
        .into_iter()
        .map(|(name, x)| (Text::from(name), AttributeValue::F64(x)))
        .collect();
    let int = |x: u32| AttributeValue::I32(x.min(i32::MAX as u32) as i32);
    other.insert(Text::from(SAMPLES), int(view.samples_per_pixel()));
    other.insert(Text::from(MAX_BOUNCES), int(settings.max_bounces));
    other.insert(Text::from(ROULETTE), int(settings.roulette_after_bounces));
    other.insert(
        Text::from(NEXT_EVENT),
        int(settings.next_event_estimation as u32),
    );
    other.insert(
        Text::from(SEED),
        AttributeValue::Text(Text::from(settings.seed.to_string().as_str())),
    );
    other.insert(
        Text::from(SCENE),
        AttributeValue::Text(Text::from(
            format!("{:016x}", scene_fingerprint(scene)).as_str(),
        )),
    );
    attributes.other = other;
    let layer = Layer::new(
        (w, h),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels.into()),
    );
    crate::io::exr::write_image(path, Image::from_layer(layer)).map_err(|source| {
        PathTracedFileError::Io {
            path: path.to_path_buf(),
            source,
        }
    })
}

/// Reads the view at `path` and checks that it is `camera`'s view (size, eye, look-at,
/// up and field of view, exactly) of `scene` ([`scene_fingerprint`]).
pub fn read_path_traced(
    path: &Path,
    camera: &Camera,
    scene: &Scene,
) -> Result<SavedView, PathTracedFileError> {
    let file = || path.to_path_buf();
    crate::io::note_input(path);
    let reader = std::fs::File::open(path)
        .map(io::BufReader::new)
        .map_err(|source| PathTracedFileError::Io {
            path: file(),
            source,
        })?;
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(reader)
        .map_err(|e| match e {
            exr::error::Error::Io(source) => PathTracedFileError::Io {
                path: file(),
                source,
            },
            other => PathTracedFileError::NotExr {
                path: file(),
                message: other.to_string(),
            },
        })?;
    let layer = &image.layer_data;
    let missing = |what: String| PathTracedFileError::NotPathTraced { path: file(), what };
    let bad = |what: String| PathTracedFileError::BadValue { path: file(), what };
    let other = &layer.attributes.other;
    let attribute = |name: &str| {
        other
            .get(&Text::from(name))
            .ok_or_else(|| missing(format!("attribute {name}")))
    };
    let double = |name: &str| match attribute(name)? {
        AttributeValue::F64(x) => Ok(*x),
        _ => Err(missing(format!("double attribute {name}"))),
    };
    let int = |name: &str| match attribute(name)? {
        AttributeValue::I32(x) if *x >= 0 => Ok(*x as u32),
        AttributeValue::I32(x) => Err(bad(format!("{name} is {x}"))),
        _ => Err(missing(format!("integer attribute {name}"))),
    };
    let text = |name: &str| match attribute(name)? {
        AttributeValue::Text(t) => Ok(t.to_string()),
        _ => Err(missing(format!("text attribute {name}"))),
    };

    // That it is a saved path-traced view at all, first: an OpenEXR image of another kind
    // (a `render -o out.exr`, which carries the same camera attributes) is told so rather
    // than that its size or camera differs (QA of issue #16).
    let markers = [SAMPLES, MAX_BOUNCES, ROULETTE, NEXT_EVENT, SEED, SCENE];
    for name in markers
        .into_iter()
        .chain(camera_attributes(camera).map(|(name, _)| name))
    {
        attribute(name)?;
    }
    for name in BANDS.into_iter().chain(SE_BANDS).chain([SE_Y, EMITTER]) {
        if !layer.channel_data.list.iter().any(|c| c.name == *name) {
            return Err(missing(format!("channel {name}")));
        }
    }

    // What the file is of, checked before its pixels are read: the scene first, as a
    // reference of another scene is wrong whatever its camera (QA of issue #16: the camera
    // was blamed, and the camera flags given then met "another scene").
    let stored = text(SCENE)?;
    let fingerprint = u64::from_str_radix(&stored, 16)
        .map_err(|_| bad(format!("scene fingerprint {stored:?} is not 16 hex digits")))?;
    let expected = scene_fingerprint(scene);
    if fingerprint != expected {
        return Err(PathTracedFileError::Scene {
            path: file(),
            found: fingerprint,
            expected,
        });
    }
    let (w, h) = (layer.size.width(), layer.size.height());
    let expected = (camera.width as usize, camera.height as usize);
    if (w, h) != expected {
        return Err(PathTracedFileError::Size {
            path: file(),
            found: (w, h),
            expected,
        });
    }
    let c = camera_attributes(camera).map(|(name, _)| name);
    let d = |i: usize| double(c[i]);
    let found = Camera {
        eye: glam::dvec3(d(0)?, d(1)?, d(2)?),
        look_at: glam::dvec3(d(3)?, d(4)?, d(5)?),
        up: glam::dvec3(d(6)?, d(7)?, d(8)?),
        fov_y_degrees: d(9)?,
        width: camera.width,
        height: camera.height,
    };
    if found != *camera {
        return Err(PathTracedFileError::Camera {
            path: file(),
            found: Box::new(found),
            expected: Box::new(*camera),
        });
    }
    let seed_text = text(SEED)?;
    let settings = PathTraceSettings {
        samples_per_pixel: int(SAMPLES)?,
        max_bounces: int(MAX_BOUNCES)?,
        roulette_after_bounces: int(ROULETTE)?,
        next_event_estimation: int(NEXT_EVENT)? != 0,
        seed: seed_text
            .parse()
            .map_err(|_| bad(format!("seed {seed_text:?} is not a whole number")))?,
    };
    if settings.check().is_err() {
        return Err(bad(format!(
            "{SAMPLES} is {}, below 2",
            settings.samples_per_pixel
        )));
    }

    // The pixels: every channel present, finite, and (but for nothing) non-negative.
    let channel = |name: &str| -> Result<Vec<f64>, PathTracedFileError> {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name == *name)
            .ok_or_else(|| missing(format!("channel {name}")))?;
        let values: Vec<f64> = c.sample_data.values_as_f32().map(f64::from).collect();
        if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(bad(format!(
                "channel {name} holds {} at pixel ({}, {})",
                values[i],
                i % w,
                i / w
            )));
        }
        Ok(values)
    };
    let bands = [channel(BANDS[0])?, channel(BANDS[1])?, channel(BANDS[2])?];
    let errors = [
        channel(SE_BANDS[0])?,
        channel(SE_BANDS[1])?,
        channel(SE_BANDS[2])?,
    ];
    let luminance_errors = channel(SE_Y)?;
    let emitter: Vec<bool> = channel(EMITTER)?.into_iter().map(|v| v > 0.5).collect();
    let rgb = |c: &[Vec<f64>; 3], i: usize| Rgb([c[0][i], c[1][i], c[2][i]]);
    let mut film = Film::new(w, h, 1, FilmContent::Radiosity);
    {
        use rayon::prelude::*;
        film.par_rows_mut().for_each(|(y, row)| {
            for (x, s) in row.iter_mut().enumerate() {
                *s = rgb(&bands, y * w + x).0;
            }
        });
    }
    let view = PathTraced::from_parts(
        film,
        (0..w * h).map(|i| rgb(&errors, i)).collect(),
        luminance_errors,
        emitter,
        settings.samples_per_pixel,
    );
    Ok(SavedView {
        view,
        camera: found,
        settings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pathtrace::path_trace;
    use crate::progress::NoProgress;
    use crate::scene::cornell_box;
    use exr::prelude::WritableImage;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("radiosity-ptfile-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    fn traced() -> (Scene, Camera, PathTraceSettings, PathTraced) {
        let scene = cornell_box().scene;
        let camera = Camera::for_scene(&scene, 7, 5);
        let settings = PathTraceSettings::DEFAULT.with_samples(16).with_seed(9);
        let view = path_trace(&scene, &camera, &settings, &NoProgress).unwrap();
        (scene, camera, settings, view)
    }

    #[test]
    fn a_view_round_trips_to_32_bits() {
        let (scene, camera, settings, view) = traced();
        let path = scratch("round-trip.exr");
        write_path_traced(&path, &view, &camera, &settings, &scene).unwrap();
        let back = read_path_traced(&path, &camera, &scene).unwrap();
        assert_eq!(back.camera, camera);
        assert_eq!(back.settings, settings);
        let r = &back.view;
        assert_eq!((r.width(), r.height(), r.samples_per_pixel()), (7, 5, 16));
        assert_eq!(r.emitter_mask(), view.emitter_mask());
        assert!(
            view.emitter_mask().iter().any(|&e| e),
            "the light is in view"
        );
        let f32_of = |x: f64| x as f32 as f64;
        for (a, b) in r.film().samples().iter().zip(view.film().samples()) {
            assert_eq!(*a, b.map(f32_of));
        }
        for (a, b) in r.standard_errors().iter().zip(view.standard_errors()) {
            assert_eq!(a.0, b.0.map(f32_of));
        }
        for (a, b) in r
            .luminance_standard_errors()
            .iter()
            .zip(view.luminance_standard_errors())
        {
            assert_eq!(*a, f32_of(*b));
        }
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn another_size_camera_or_scene_is_refused() {
        let (scene, camera, settings, view) = traced();
        let path = scratch("refusals.exr");
        write_path_traced(&path, &view, &camera, &settings, &scene).unwrap();
        let name = path.display().to_string();

        let wider = Camera { width: 8, ..camera };
        let err = read_path_traced(&path, &wider, &scene).unwrap_err();
        assert!(matches!(
            err,
            PathTracedFileError::Size {
                found: (7, 5),
                expected: (8, 5),
                ..
            }
        ));
        let text = err.to_string();
        assert!(
            text.contains(&name) && text.contains("7 x 5") && text.contains("8 x 5"),
            "{text}"
        );

        let moved = Camera {
            eye: camera.eye + glam::DVec3::X,
            ..camera
        };
        let err = read_path_traced(&path, &moved, &scene).unwrap_err();
        let text = err.to_string();
        assert!(matches!(err, PathTracedFileError::Camera { .. }), "{text}");
        assert!(
            text.contains(&name) && text.contains("eye [") && text.contains(", not eye ["),
            "{text}"
        );

        let mut other = scene.clone();
        other.surfaces[0].reflectance = Rgb([0.1; 3]);
        let err = read_path_traced(&path, &camera, &other).unwrap_err();
        assert!(matches!(err, PathTracedFileError::Scene { .. }), "{err}");

        // Not an OpenEXR file, and no file at all.
        let junk = scratch("junk.exr");
        std::fs::write(&junk, b"not an image").unwrap();
        let err = read_path_traced(&junk, &camera, &scene).unwrap_err();
        assert!(matches!(err, PathTracedFileError::NotExr { .. }), "{err}");
        let gone = scratch("missing.exr");
        let err = read_path_traced(&gone, &camera, &scene).unwrap_err();
        assert!(matches!(err, PathTracedFileError::Io { .. }), "{err}");
        for p in [path, junk] {
            std::fs::remove_file(p).unwrap();
        }
    }

    #[test]
    fn an_exr_without_the_attributes_is_not_a_saved_view() {
        // A plain RGB OpenEXR image of the right size, as another program writes it.
        let (scene, camera, _, _) = traced();
        let path = scratch("plain.exr");
        let channels: Vec<AnyChannel<FlatSamples>> = BANDS
            .iter()
            .map(|b| AnyChannel::new(*b, FlatSamples::F32(vec![0.5; 35])))
            .collect();
        let layer = Layer::new(
            (7, 5),
            LayerAttributes::named("plain"),
            Encoding::UNCOMPRESSED,
            AnyChannels::sort(channels.into()),
        );
        Image::from_layer(layer).write().to_file(&path).unwrap();
        let err = read_path_traced(&path, &camera, &scene).unwrap_err();
        assert!(
            matches!(err, PathTracedFileError::NotPathTraced { .. }),
            "{err}"
        );
        assert!(err.to_string().contains(SAMPLES), "{err}");
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn a_render_exr_is_not_a_saved_view_whatever_its_size_or_camera() {
        // `render -o out.exr` carries the camera attributes but is another format: that is
        // said first, not that its size or camera differs (QA of issue #16).
        let (scene, camera, _, _) = traced();
        let path = scratch("render.exr");
        let other = Camera {
            width: 4,
            height: 3,
            fov_y_degrees: camera.fov_y_degrees + 5.0,
            ..camera
        };
        crate::io::exr::write_radiance(&path, 4, 3, &[[1.0; 3]; 12], &other, "test", "metres")
            .unwrap();
        let err = read_path_traced(&path, &camera, &scene).unwrap_err();
        assert!(
            matches!(err, PathTracedFileError::NotPathTraced { .. }),
            "{err}"
        );
        std::fs::remove_file(&path).unwrap();
    }

    #[test]
    fn the_fingerprint_follows_geometry_and_colour() {
        let a = cornell_box().scene;
        assert_eq!(
            scene_fingerprint(&a),
            scene_fingerprint(&cornell_box().scene)
        );
        let mut b = a.clone();
        b.surfaces[3].vertices[1].x += 1e-9;
        assert_ne!(scene_fingerprint(&a), scene_fingerprint(&b));
    }
}
