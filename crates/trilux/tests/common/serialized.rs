//! Mitsuba serialized mesh files written by hand, following Mitsuba 3's
//! documented layout (`src/shapes/serialized.cpp`): the zlib streams are
//! uncompressed ("stored") deflate blocks, a valid zlib stream that needs
//! no compressor.

/// A mesh's data before compression.
pub struct Mesh<'a> {
    /// Positions.
    pub positions: &'a [[f64; 3]],
    /// Triangles.
    pub triangles: &'a [[u32; 3]],
    /// Texture coordinates (flag 0x0002), if any.
    pub texcoords: Option<&'a [[f64; 2]]>,
    /// Doubles (flag 0x2000) instead of floats.
    pub double: bool,
}

/// RFC 1950's Adler-32.
fn adler32(bytes: &[u8]) -> u32 {
    let (mut a, mut b) = (1u32, 0u32);
    for &x in bytes {
        a = (a + u32::from(x)) % 65521;
        b = (b + a) % 65521;
    }
    (b << 16) | a
}

/// `data` as a zlib stream of stored blocks.
pub fn zlib_stored(data: &[u8]) -> Vec<u8> {
    let mut out = vec![0x78, 0x01];
    let chunks: Vec<&[u8]> = if data.is_empty() {
        vec![&[]]
    } else {
        data.chunks(65535).collect()
    };
    for (i, chunk) in chunks.iter().enumerate() {
        out.push(u8::from(i + 1 == chunks.len()));
        let len = chunk.len() as u16;
        out.extend(len.to_le_bytes());
        out.extend((!len).to_le_bytes());
        out.extend(*chunk);
    }
    out.extend(adler32(data).to_be_bytes());
    out
}

/// The uncompressed stream of one version 4 mesh.
pub fn mesh_data(m: &Mesh<'_>) -> Vec<u8> {
    let flags: u32 =
        if m.double { 0x2000 } else { 0x1000 } | if m.texcoords.is_some() { 2 } else { 0 };
    let mut d = flags.to_le_bytes().to_vec();
    d.extend(b"mesh\0");
    d.extend((m.positions.len() as u64).to_le_bytes());
    d.extend((m.triangles.len() as u64).to_le_bytes());
    let float = |d: &mut Vec<u8>, x: f64| {
        if m.double {
            d.extend(x.to_le_bytes());
        } else {
            d.extend((x as f32).to_le_bytes());
        }
    };
    m.positions.iter().flatten().for_each(|&x| float(&mut d, x));
    m.texcoords
        .iter()
        .copied()
        .flatten()
        .flatten()
        .for_each(|&x| float(&mut d, x));
    m.triangles
        .iter()
        .flatten()
        .for_each(|i| d.extend(i.to_le_bytes()));
    d
}

/// A version 4 file of the meshes whose streams are `streams`, with its
/// end-of-file dictionary.
pub fn file(streams: &[Vec<u8>]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut offsets = Vec::new();
    for s in streams {
        offsets.push(out.len() as u64);
        out.extend(0x041Cu16.to_le_bytes());
        out.extend(4u16.to_le_bytes());
        out.extend(zlib_stored(s));
    }
    offsets.iter().for_each(|o| out.extend(o.to_le_bytes()));
    out.extend((streams.len() as u32).to_le_bytes());
    out
}
