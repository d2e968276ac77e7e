//! Rendered images as PNG files (8-bit RGB, as [`crate::render::render`] makes them).

use std::io;
use std::path::Path;

use image::{ImageEncoder, RgbImage};

/// Writes `image` as a PNG file at `path`, atomically (a temporary file beside it, then a
/// rename; see [`crate::io::write_atomically`]).
pub fn write_png(image: &RgbImage, path: &Path) -> io::Result<()> {
    crate::io::write_atomically(path, |w| {
        image::codecs::png::PngEncoder::new(w)
            .write_image(
                image.as_raw(),
                image.width(),
                image.height(),
                image::ExtendedColorType::Rgb8,
            )
            .map_err(io::Error::other)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_round_trips() {
        let img = RgbImage::from_fn(13, 7, |x, y| image::Rgb([x as u8 * 19, y as u8 * 36, 153]));
        let dir = std::env::temp_dir().join(format!("radiosity-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("view.png");
        write_png(&img, &path).unwrap();
        let back = image::open(&path).unwrap().to_rgb8();
        assert_eq!(back, img);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
