//! How irpol draws: the embedded plot font, the series palette and PNG encoding, shared by the
//! render previews ([`crate::output`]) and the reports ([`crate::report`]). Plot text uses the
//! DejaVu Sans font embedded in the binary, so figures render on a machine without any system fonts.

use std::sync::Once;

/// Font family name under which the embedded DejaVu Sans is registered with plotters.
pub const FONT: &str = "sans-serif";

/// Registers the embedded fonts with plotters once per process.
pub fn register_fonts() {
    static REGISTER: Once = Once::new();
    REGISTER.call_once(|| {
        use plotters::style::FontStyle;
        // DejaVu ships valid TrueType data; a failure here would be a build defect, not user input.
        plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular())
            .unwrap_or_else(|_| panic!("embedded DejaVu Sans font is invalid"));
        plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold())
            .unwrap_or_else(|_| panic!("embedded DejaVu Sans Bold font is invalid"));
    });
}

/// Tableau 20: the ten Tableau 10 colours (readable on white and in grey print), then their light
/// companions. Series colours of every plot.
pub const TABLEAU20: [plotters::style::RGBColor; 20] = {
    use plotters::style::RGBColor as C;
    [
        C(31, 119, 180),
        C(255, 127, 14),
        C(44, 160, 44),
        C(214, 39, 40),
        C(148, 103, 189),
        C(140, 86, 75),
        C(227, 119, 194),
        C(127, 127, 127),
        C(188, 189, 34),
        C(23, 190, 207),
        C(174, 199, 232),
        C(255, 187, 120),
        C(152, 223, 138),
        C(255, 152, 150),
        C(197, 176, 213),
        C(196, 156, 148),
        C(247, 182, 210),
        C(199, 199, 199),
        C(219, 219, 141),
        C(158, 218, 229),
    ]
};

/// PNG bytes of an RGB8 buffer (so the file can be written atomically).
pub fn encode_png(rgb: &[u8], width: u32, height: u32) -> Result<Vec<u8>, image::ImageError> {
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        rgb,
        width,
        height,
        image::ExtendedColorType::Rgb8,
    )?;
    Ok(bytes)
}
