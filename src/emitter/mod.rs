//! Light sources beyond the surfaces themselves: the sun (DESIGN §1.7). The sky and ground of the
//! environment model are in `scene::environment`.

pub mod sun;
