//! Linear images as OpenEXR files (`render -o out.exr`, `pathtrace -o out.exr`), for
//! compositing and measurement: no exposure, no clamping, no gamma.
//!
//! One scan-line layer, ZIP-compressed (lossless), channels `R`, `G`, `B` as 32-bit floats
//! (7 significant digits), pixels row by row from the top-left corner. Each value is the
//! pixel's **radiance** L per band, in the scene's emission units per steradian: the
//! renderer's and the path tracer's films hold the radiosity B seen through the pixel (a
//! surface of uniform radiosity B shows as B), and a Lambertian surface of radiosity B has
//! radiance L = B / pi in every direction, so the file holds film / pi. A closed box whose
//! surfaces all emit E and reflect rho (B = E / (1 - rho)) shows E / (pi (1 - rho))
//! everywhere. (The path tracer's *reference* files, [`super::path_traced_file`], keep B
//! itself, as the comparison needs; they are another format.)
//!
//! Layer attributes say what the file holds: `radiosity.quantity` ("radiance = radiosity
//! / pi, scene emission units per steradian"), `radiosity.unit` ([`UNIT`]: the values'
//! unit, cd/m^2 for a photometric scene), `radiosity.lengthUnit` (the scene's length unit
//! in words, as the importers give it: `scene units`, `metres = the file's numbers x 0.001; unscaled, metres (glTF's unit)`, ...),
//! the camera (`radiosity.eye.x` ... `radiosity.fovY`, as in the reference files) and the
//! software.

use std::collections::HashMap;
use std::io::{self, Write};
use std::path::Path;

use exr::prelude::{
    AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, Layer, LayerAttributes,
    Text, WritableImage,
};

use crate::render::Camera;

/// The `radiosity.quantity` attribute of a linear image.
pub const QUANTITY: &str = "radiance = radiosity / pi, scene emission units per steradian";

/// The `radiosity.unit` attribute of a linear image: the unit of its values.
pub const UNIT: &str = "the scene's emission unit per steradian: cd/m^2 where E is in lm/m^2 \
                        (photometric scenes), W/(m^2 sr) where E is in W/m^2";

/// Writes `image` (a layer with its attributes) to `path`, atomically (see
/// [`crate::io::write_atomically`]), its header's attributes in the order of their names
/// ([`sort_header_attributes`]); the `exr` crate's errors become I/O errors.
pub(crate) fn write_image(
    path: &Path,
    image: Image<Layer<AnyChannels<FlatSamples>>>,
) -> io::Result<()> {
    let mut bytes = io::Cursor::new(Vec::new());
    image.write().to_buffered(&mut bytes).map_err(|e| match e {
        exr::error::Error::Io(e) => e,
        other => io::Error::other(other.to_string()),
    })?;
    let mut bytes = bytes.into_inner();
    sort_header_attributes(&mut bytes);
    crate::io::write_atomically(path, |out| out.write_all(&bytes))
}

/// Puts the attributes of a single-part OpenEXR file's header in the order of their names,
/// in place. The `exr` crate writes a layer's own attributes from a `HashMap` whose order
/// changes from run to run, so the same image made different files (QA of issue #16);
/// sorted, the same image is the same bytes. The header keeps its length, so the offsets
/// that follow it stay right. A header that does not parse as one (or a multi-part file)
/// is left as it is.
///
/// The layout (OpenEXR file layout, "Header"): the magic number and version field (8
/// bytes), then attributes, each a name and a type name ended by 0 bytes, a 4-byte
/// little-endian size and that many bytes of value, and a 0 byte that ends the header.
fn sort_header_attributes(bytes: &mut [u8]) {
    const MULTIPART: u8 = 0x10; // bit 12 of the version field, in its second byte
    if bytes.len() < 8 || bytes[..4] != [0x76, 0x2f, 0x31, 0x01] || bytes[5] & MULTIPART != 0 {
        return;
    }
    let zero_after = |from: usize| {
        bytes
            .get(from..)?
            .iter()
            .position(|&b| b == 0)
            .map(|k| from + k)
    };
    let mut spans: Vec<(usize, usize, usize)> = Vec::new(); // (start, name end, end)
    let mut at = 8;
    loop {
        match bytes.get(at) {
            None => return,
            Some(0) => break,
            Some(_) => {}
        }
        let Some(name_end) = zero_after(at) else {
            return;
        };
        let Some(type_end) = zero_after(name_end + 1) else {
            return;
        };
        let Some(size) = bytes.get(type_end + 1..type_end + 5) else {
            return;
        };
        let size = u32::from_le_bytes([size[0], size[1], size[2], size[3]]) as usize;
        let end = type_end + 5 + size;
        if end > bytes.len() {
            return;
        }
        spans.push((at, name_end, end));
        at = end;
    }
    let mut sorted = spans.clone();
    sorted.sort_by(|a, b| bytes[a.0..a.1].cmp(&bytes[b.0..b.1]));
    let header: Vec<u8> = sorted
        .iter()
        .flat_map(|&(start, _, end)| bytes[start..end].iter().copied())
        .collect();
    bytes[8..at].copy_from_slice(&header);
}

/// Writes a `width` x `height` linear image whose pixels (row by row from the top left)
/// hold the radiosity `film_b` seen through them, as radiance `film_b / pi` (module
/// documentation), at `path`, atomically. `camera`, `software` and the scene's length unit
/// in words, `length_unit`, go into the attributes.
///
/// Returns an `InvalidInput` error, writing nothing, when `film_b` does not have
/// `width * height` pixels.
pub fn write_radiance(
    path: &Path,
    width: usize,
    height: usize,
    film_b: &[[f64; 3]],
    camera: &Camera,
    software: &str,
    length_unit: &str,
) -> io::Result<()> {
    if film_b.len() != width * height {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{} pixels for a {width} x {height} image", film_b.len()),
        ));
    }
    let channels: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B"]
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let values = film_b
                .iter()
                .map(|p| (p[k] / std::f64::consts::PI) as f32)
                .collect();
            AnyChannel::new(*name, FlatSamples::F32(values))
        })
        .collect();
    let mut attributes = LayerAttributes::named("radiance");
    attributes.software_name = Some(Text::from(software));
    let mut other: HashMap<Text, AttributeValue> =
        super::path_traced_file::camera_attributes(camera)
            .into_iter()
            .map(|(name, x)| (Text::from(name), AttributeValue::F64(x)))
            .collect();
    other.insert(
        Text::from("radiosity.quantity"),
        AttributeValue::Text(Text::from(QUANTITY)),
    );
    other.insert(
        Text::from("radiosity.unit"),
        AttributeValue::Text(Text::from(UNIT)),
    );
    other.insert(
        Text::from("radiosity.lengthUnit"),
        AttributeValue::Text(Text::from(length_unit)),
    );
    attributes.other = other;
    let layer = Layer::new(
        (width, height),
        attributes,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(channels.into()),
    );
    write_image(path, Image::from_layer(layer))
}

/// A linear image read back: width, height and the `R`, `G`, `B` values row by row (for
/// tests and scripts; any RGB float OpenEXR file reads).
pub fn read_rgb(path: &Path) -> Result<(usize, usize, Vec<[f32; 3]>), exr::error::Error> {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| {
            (
                size.width(),
                vec![[0.0f32; 3]; size.width() * size.height()],
            )
        },
        |(w, pixels), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels[pos.y() * *w + pos.x()] = [r, g, b];
        },
    )?;
    let size = image.layer_data.size;
    let (_, pixels) = image.layer_data.channel_data.pixels;
    Ok((size.width(), size.height(), pixels))
}

/// The text attributes of the first layer of the OpenEXR file at `path` (name -> value),
/// for tests and scripts.
pub fn text_attributes(path: &Path) -> Result<HashMap<String, String>, exr::error::Error> {
    let meta = exr::meta::MetaData::read_from_file(path, false)?;
    let mut out = HashMap::new();
    if let Some(header) = meta.headers.first() {
        for (name, value) in &header.own_attributes.other {
            if let AttributeValue::Text(t) = value {
                out.insert(name.to_string(), t.to_string());
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// A camera 3 units before the origin, looking at it, `width` x `height` pixels.
    fn camera(width: u32, height: u32) -> Camera {
        Camera {
            eye: DVec3::new(0.0, 0.0, -3.0),
            look_at: DVec3::ZERO,
            up: DVec3::Y,
            fov_y_degrees: 40.0,
            width,
            height,
        }
    }

    #[test]
    fn radiance_is_radiosity_over_pi_unclamped_and_in_order() {
        // Values far above 1 and a pixel order that a transposition would break.
        let film: Vec<[f64; 3]> = (0..6)
            .map(|i| [i as f64 * 10.0, 0.5, std::f64::consts::PI * 1000.0])
            .collect();
        let camera = camera(3, 2);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("view.exr");
        write_radiance(&path, 3, 2, &film, &camera, "test", "metres x 0.001").unwrap();
        let attributes = text_attributes(&path).unwrap();
        assert_eq!(attributes["radiosity.quantity"], QUANTITY);
        assert_eq!(attributes["radiosity.unit"], UNIT);
        assert_eq!(attributes["radiosity.lengthUnit"], "metres x 0.001");
        let (w, h, pixels) = read_rgb(&path).unwrap();
        assert_eq!((w, h), (3, 2));
        for (i, p) in pixels.iter().enumerate() {
            let expect = [
                i as f64 * 10.0 / std::f64::consts::PI,
                0.5 / std::f64::consts::PI,
                1000.0,
            ];
            for k in 0..3 {
                // f32 keeps 24 bits: a relative error of at most 2^-24 (6e-8).
                let err = (p[k] as f64 - expect[k]).abs();
                assert!(
                    err <= 1e-7 * expect[k].abs(),
                    "pixel {i} band {k}: {p:?} vs {expect:?}"
                );
            }
        }
        // A pixel count that is not the size's is refused, and nothing is written.
        let other = dir.path().join("bad.exr");
        let err = write_radiance(&other, 2, 2, &film, &camera, "test", "metres").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::InvalidInput);
        assert!(!other.exists());
    }

    /// QA of issue #16: the same image written twice made two files (the header's
    /// attributes came in a `HashMap`'s order). Written again and again, it is the same
    /// bytes, its attributes in the order of their names, and it reads back.
    #[test]
    fn the_same_image_is_the_same_bytes() {
        let film = vec![[1.0, 2.0, 3.0]; 4];
        let camera = camera(2, 2);
        let dir = tempfile::tempdir().unwrap();
        let files: Vec<Vec<u8>> = (0..8)
            .map(|k| {
                let path = dir.path().join(format!("{k}.exr"));
                write_radiance(&path, 2, 2, &film, &camera, "test", "metres").unwrap();
                assert_eq!(text_attributes(&path).unwrap()["radiosity.unit"], UNIT);
                assert_eq!(read_rgb(&path).unwrap().2.len(), 4);
                std::fs::read(&path).unwrap()
            })
            .collect();
        for f in &files[1..] {
            assert!(f == &files[0], "two writes of one image differ");
        }
        // The names in the header, in order.
        let mut names = Vec::new();
        let mut at = 8;
        let bytes = &files[0];
        while bytes[at] != 0 {
            let name_end = at + bytes[at..].iter().position(|&b| b == 0).unwrap();
            let type_end =
                name_end + 1 + bytes[name_end + 1..].iter().position(|&b| b == 0).unwrap();
            let size = u32::from_le_bytes(bytes[type_end + 1..type_end + 5].try_into().unwrap());
            names.push(bytes[at..name_end].to_vec());
            at = type_end + 5 + size as usize;
        }
        assert!(names.len() > 10, "{} attributes", names.len());
        assert!(names.windows(2).all(|w| w[0] < w[1]), "not in order");
    }
}
