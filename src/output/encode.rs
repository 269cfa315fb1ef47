//! The float image encoders of a render's outputs: uncompressed TIFFs and the multi-channel
//! OpenEXR, each carrying its JSON metadata.

use super::channel::Channel;
use super::ground_truth::TruthData;
use std::io::Cursor;

/// Single-channel 32-bit IEEE float TIFF (SampleFormat = 3), uncompressed.
/// An uncompressed TIFF of `data` (32-bit float gray, float RGB for vectors, 32-bit unsigned for
/// IDs) with `description` (JSON metadata) in its ImageDescription tag.
pub(super) fn encode_tiff(
    width: usize,
    height: usize,
    data: &TruthData,
    description: &str,
) -> std::io::Result<Vec<u8>> {
    use tiff::encoder::colortype::{ColorType, Gray32, Gray32Float, RGB32Float};
    use tiff::encoder::{TiffEncoder, TiffValue};
    use tiff::tags::Tag;
    fn write<C: ColorType>(
        encoder: &mut TiffEncoder<&mut Cursor<Vec<u8>>>,
        (width, height): (u32, u32),
        data: &[C::Inner],
        description: &str,
    ) -> tiff::TiffResult<()>
    where
        [C::Inner]: TiffValue,
    {
        let mut image = encoder.new_image::<C>(width, height)?;
        image
            .encoder()
            .write_tag(Tag::ImageDescription, description)?;
        image.write_data(data)
    }
    let mut bytes = Cursor::new(Vec::new());
    let mut encoder = TiffEncoder::new(&mut bytes).map_err(std::io::Error::other)?;
    let size = (width as u32, height as u32);
    match data {
        TruthData::Float(v) => write::<Gray32Float>(&mut encoder, size, v, description),
        TruthData::Vector(v) => write::<RGB32Float>(&mut encoder, size, v, description),
        TruthData::Id(v) => write::<Gray32>(&mut encoder, size, v, description),
    }
    .map_err(std::io::Error::other)?;
    Ok(bytes.into_inner())
}

/// One OpenEXR layer "stokes" with a 32-bit float channel per [`Channel`], uncompressed.
pub(super) fn encode_exr(
    width: usize,
    height: usize,
    channels: &[(Channel, Vec<f32>)],
    description: &str,
) -> std::io::Result<Vec<u8>> {
    use exr::prelude::*;
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .iter()
        .map(|(c, data)| AnyChannel::new(c.name(), FlatSamples::F32(data.clone())))
        .collect();
    let layer = Layer::new(
        (width, height),
        LayerAttributes::named("stokes"),
        // Noisy float data does not compress; uncompressed is as small and fastest.
        Encoding::UNCOMPRESSED,
        AnyChannels::sort(list),
    );
    let mut bytes = Cursor::new(Vec::new());
    let mut image = Image::from_layer(layer);
    image.attributes.other.insert(
        Text::from("irpol"),
        AttributeValue::Text(Text::from(description)),
    );
    image
        .write()
        .to_buffered(&mut bytes)
        .map_err(std::io::Error::other)?;
    Ok(bytes.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiff_and_exr_round_trip() {
        let (w, h) = (5, 3);
        let data: Vec<f32> = (0..15).map(|i| i as f32 * 0.25 - 1.0).collect();
        let tiff = encode_tiff(w, h, &TruthData::Float(data.clone()), "{\"a\": 1}").unwrap();
        let mut decoder = tiff::decoder::Decoder::new(Cursor::new(tiff)).unwrap();
        assert_eq!(decoder.dimensions().unwrap(), (5, 3));
        let description = decoder
            .get_tag_ascii_string(tiff::tags::Tag::ImageDescription)
            .unwrap();
        assert_eq!(description, "{\"a\": 1}");
        match decoder.read_image().unwrap() {
            tiff::decoder::DecodingResult::F32(back) => assert_eq!(back, data),
            _ => panic!("not a float TIFF"),
        }
        let ids = TruthData::Id((0..15).collect());
        let mut decoder =
            tiff::decoder::Decoder::new(Cursor::new(encode_tiff(w, h, &ids, "").unwrap())).unwrap();
        match decoder.read_image().unwrap() {
            tiff::decoder::DecodingResult::U32(back) => {
                assert_eq!(back, (0..15).collect::<Vec<_>>())
            }
            _ => panic!("not a 32-bit unsigned TIFF"),
        }
        let channels = vec![(Channel::S0, data.clone()), (Channel::Dolp, vec![0.5; 15])];
        let exr_bytes = encode_exr(w, h, &channels, "{}").unwrap();
        use exr::prelude::{ReadChannels, ReadLayers};
        let image = exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_buffered(Cursor::new(exr_bytes))
            .unwrap();
        let layer = &image.layer_data;
        assert_eq!(layer.size, exr::math::Vec2(5, 3));
        let names: Vec<String> = layer
            .channel_data
            .list
            .iter()
            .map(|c| c.name.to_string())
            .collect();
        assert_eq!(names, vec!["DoLP", "S0"]);
        let key = exr::prelude::Text::from("irpol");
        let irpol = image
            .attributes
            .other
            .get(&key)
            .or(layer.attributes.other.get(&key));
        assert!(
            matches!(irpol, Some(exr::meta::attribute::AttributeValue::Text(t)) if t.as_slice() == b"{}"),
            "{irpol:?}"
        );
        let s0: Vec<f32> = layer.channel_data.list[1]
            .sample_data
            .values_as_f32()
            .collect();
        assert_eq!(s0, data);
    }
}
