//! Radiance RGBE images (`.hdr`, Greg Ward's format): a text header
//! ending in a blank line, the resolution line `-Y H +X W` (rows from the
//! top, the one orientation read), then each row flat (4 bytes a pixel)
//! or run-length encoded per channel (the row starts 2, 2, W/256, W%256).
//! A pixel (R, G, B, E) is (R, G, B) · 2^(E − 136), 0 where E is 0, as
//! Bruce Walter's reference reader (which Mitsuba 3's `Bitmap` uses)
//! decodes it.

/// Width, height and linear RGB texels (rows from the top).
type Texels = (usize, usize, Vec<[f32; 3]>);

/// Decodes `bytes`, refusing images of more than `max_texels` texels.
pub(crate) fn decode(bytes: &[u8], max_texels: u64) -> Result<Texels, String> {
    let bad = |m: &str| format!("malformed Radiance (.hdr) image: {m}");
    let mut pos = 0;
    let mut format_ok = true;
    loop {
        let l = line(bytes, &mut pos).ok_or_else(|| bad("the header does not end"))?;
        if l.is_empty() {
            break;
        }
        if let Some(f) = l.strip_prefix(b"FORMAT=") {
            format_ok = f == b"32-bit_rle_rgbe";
        }
    }
    if !format_ok {
        return Err(bad("only FORMAT=32-bit_rle_rgbe is read"));
    }
    let res = line(bytes, &mut pos).ok_or_else(|| bad("no resolution line"))?;
    let res = std::str::from_utf8(res).map_err(|_| bad("the resolution line is not text"))?;
    let words: Vec<&str> = res.split_whitespace().collect();
    let (h, w) = match words.as_slice() {
        ["-Y", h, "+X", w] => (h.parse::<usize>(), w.parse::<usize>()),
        _ => return Err(bad("the resolution line is not \"-Y H +X W\"")),
    };
    let (Ok(h), Ok(w)) = (h, w) else {
        return Err(bad("the resolution is not two whole numbers"));
    };
    if w == 0 || h == 0 || (w as u64) * (h as u64) > max_texels {
        return Err(format!(
            "image of {w} × {h} texels is empty or beyond the limit of {max_texels} texels (docs/limits.md)"
        ));
    }
    let data = &bytes[pos..];
    let mut at = 0;
    let mut texels = Vec::with_capacity(w * h);
    let mut row = vec![[0u8; 4]; w];
    for _ in 0..h {
        read_row(data, &mut at, &mut row)
            .ok_or_else(|| bad("the pixel data ends early or is malformed"))?;
        texels.extend(row.iter().map(|p| {
            if p[3] == 0 {
                [0.0; 3]
            } else {
                let f = 2f32.powi(i32::from(p[3]) - 136);
                [
                    f32::from(p[0]) * f,
                    f32::from(p[1]) * f,
                    f32::from(p[2]) * f,
                ]
            }
        }));
    }
    Ok((w, h, texels))
}

/// The line of `bytes` from `*pos` (without its newline), `*pos` moved
/// past it; `None` when no newline ends it.
fn line<'a>(bytes: &'a [u8], pos: &mut usize) -> Option<&'a [u8]> {
    let rest = bytes.get(*pos..)?;
    let end = rest.iter().position(|&b| b == b'\n')?;
    *pos += end + 1;
    Some(&rest[..end])
}

/// One row into `row`, from `data[*at..]`; `None` when it is malformed.
fn read_row(data: &[u8], at: &mut usize, row: &mut [[u8; 4]]) -> Option<()> {
    let w = row.len();
    let head = data.get(*at..*at + 4)?;
    let rle = (8..32768).contains(&w) && head[0] == 2 && head[1] == 2 && head[2] & 0x80 == 0;
    if !rle {
        for p in row.iter_mut() {
            p.copy_from_slice(data.get(*at..*at + 4)?);
            *at += 4;
        }
        return Some(());
    }
    if ((usize::from(head[2]) << 8) | usize::from(head[3])) != w {
        return None;
    }
    *at += 4;
    for c in 0..4 {
        let mut x = 0;
        while x < w {
            let count = usize::from(*data.get(*at)?);
            *at += 1;
            if count > 128 {
                let n = count - 128;
                let v = *data.get(*at)?;
                *at += 1;
                for p in row.get_mut(x..x + n)? {
                    p[c] = v;
                }
                x += n;
            } else {
                if count == 0 {
                    return None;
                }
                for (p, &v) in row
                    .get_mut(x..x + count)?
                    .iter_mut()
                    .zip(data.get(*at..*at + count)?)
                {
                    p[c] = v;
                }
                *at += count;
                x += count;
            }
        }
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_and_run_length_rows_decode() {
        let mut f = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 8\n".to_vec();
        // Row 0 flat: (128, 64, 32, 129) is (128, 64, 32) · 2^(129 − 136).
        for _ in 0..8 {
            f.extend_from_slice(&[128, 64, 32, 129]);
        }
        // Row 1 run-length encoded: each channel one run of 8.
        f.extend_from_slice(&[2, 2, 0, 8]);
        for v in [128u8, 128, 128, 128] {
            f.extend_from_slice(&[128 + 8, v]);
        }
        let (w, h, t) = decode(&f, 1 << 20).unwrap();
        assert_eq!((w, h), (8, 2));
        assert_eq!(t[0], [1.0, 0.5, 0.25]);
        assert_eq!(t[15], [0.5, 0.5, 0.5]);
        assert!(decode(&f[..f.len() - 1], 1 << 20).is_err());
        assert!(decode(&f, 15).is_err());
    }
}
