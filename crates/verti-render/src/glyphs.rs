//! Horizontal metrics of the vendored font, read from its TrueType tables.
//!
//! `plotters` 0.3.7 places each glyph's bitmap at the pen position and drops the glyph's left
//! side bearing, so letters drift by up to a pixel or two at small sizes ("cl" reads as "d").
//! Text on world maps is therefore laid out here, one glyph at a time, from the font's own
//! advance widths and bearings (`cmap` format 4, `hhea`, `hmtx`), and only the rasterising is
//! left to `plotters`.

use std::collections::HashMap;
use std::sync::OnceLock;

/// Advance width and left side bearing of a glyph, font units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct GlyphMetrics {
    pub advance: f64,
    pub lsb: f64,
}

#[derive(Debug)]
pub(crate) struct FontMetrics {
    /// ascender - descender (`hhea`): `ab_glyph` scales a font so this spans the pixel size.
    pub height: f64,
    glyphs: HashMap<char, GlyphMetrics>,
    fallback: GlyphMetrics,
}

impl FontMetrics {
    /// Metrics of `c` in font units (the `.notdef` glyph's for characters the font lacks).
    pub fn glyph(&self, c: char) -> GlyphMetrics {
        self.glyphs.get(&c).copied().unwrap_or(self.fallback)
    }
}

fn u16_at(d: &[u8], o: usize) -> Option<u16> {
    Some(u16::from_be_bytes([*d.get(o)?, *d.get(o + 1)?]))
}
fn i16_at(d: &[u8], o: usize) -> Option<i16> {
    u16_at(d, o).map(|v| v as i16)
}
fn u32_at(d: &[u8], o: usize) -> Option<u32> {
    Some(u32::from_be_bytes([
        *d.get(o)?,
        *d.get(o + 1)?,
        *d.get(o + 2)?,
        *d.get(o + 3)?,
    ]))
}

fn table<'a>(font: &'a [u8], tag: &[u8; 4]) -> Option<&'a [u8]> {
    let n = usize::from(u16_at(font, 4)?);
    (0..n).find_map(|i| {
        let rec = 12 + 16 * i;
        (font.get(rec..rec + 4)? == tag).then_some(())?;
        let off = u32_at(font, rec + 8)? as usize;
        let len = u32_at(font, rec + 12)? as usize;
        font.get(off..off.checked_add(len)?)
    })
}

/// char -> glyph id from the Unicode BMP (format 4) subtable of `cmap`.
fn cmap4(cmap: &[u8]) -> Option<HashMap<char, u16>> {
    let n = usize::from(u16_at(cmap, 2)?);
    let sub = (0..n).find_map(|i| {
        let rec = 4 + 8 * i;
        let (platform, encoding) = (u16_at(cmap, rec)?, u16_at(cmap, rec + 2)?);
        let off = u32_at(cmap, rec + 4)? as usize;
        ((platform == 3 && encoding == 1) || platform == 0)
            .then_some(())
            .and_then(|_| (u16_at(cmap, off)? == 4).then_some(off))
    })?;
    let t = cmap.get(sub..)?;
    let segs = usize::from(u16_at(t, 6)? / 2);
    let (ends, starts, deltas, ranges) = (14, 16 + 2 * segs, 16 + 4 * segs, 16 + 6 * segs);
    let mut map = HashMap::new();
    for s in 0..segs {
        let (end, start) = (u16_at(t, ends + 2 * s)?, u16_at(t, starts + 2 * s)?);
        let (delta, range) = (u16_at(t, deltas + 2 * s)?, u16_at(t, ranges + 2 * s)?);
        for code in start..=end {
            if code == 0xFFFF {
                break;
            }
            let gid = if range == 0 {
                code.wrapping_add(delta)
            } else {
                let at = ranges + 2 * s + usize::from(range) + 2 * usize::from(code - start);
                match u16_at(t, at)? {
                    0 => 0,
                    g => g.wrapping_add(delta),
                }
            };
            if let (Some(c), true) = (char::from_u32(u32::from(code)), gid != 0) {
                map.insert(c, gid);
            }
        }
    }
    Some(map)
}

fn parse(font: &[u8]) -> Option<FontMetrics> {
    let hhea = table(font, b"hhea")?;
    let hmtx = table(font, b"hmtx")?;
    let height = f64::from(i16_at(hhea, 4)?) - f64::from(i16_at(hhea, 6)?);
    let long = usize::from(u16_at(hhea, 34)?);
    if long == 0 || height <= 0.0 {
        return None;
    }
    let metrics = |gid: u16| -> Option<GlyphMetrics> {
        let g = usize::from(gid);
        if g < long {
            Some(GlyphMetrics {
                advance: f64::from(u16_at(hmtx, 4 * g)?),
                lsb: f64::from(i16_at(hmtx, 4 * g + 2)?),
            })
        } else {
            Some(GlyphMetrics {
                advance: f64::from(u16_at(hmtx, 4 * (long - 1))?),
                lsb: f64::from(i16_at(hmtx, 4 * long + 2 * (g - long))?),
            })
        }
    };
    let glyphs = cmap4(table(font, b"cmap")?)?
        .into_iter()
        .filter_map(|(c, gid)| Some((c, metrics(gid)?)))
        .collect();
    Some(FontMetrics {
        height,
        glyphs,
        fallback: metrics(0)?,
    })
}

/// Metrics of the vendored DejaVu Sans (`None` only if the file were corrupt).
pub(crate) fn metrics(font: &'static [u8]) -> Option<&'static FontMetrics> {
    static METRICS: OnceLock<Option<FontMetrics>> = OnceLock::new();
    METRICS.get_or_init(|| parse(font)).as_ref()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_dejavu_metrics() {
        let m = metrics(include_bytes!("../assets/DejaVuSans.ttf")).expect("font tables");
        // DejaVu Sans: ascender 1901, descender -483; "l" is narrower than "m"; a space has no
        // ink but an advance.
        assert_eq!(m.height, 2384.0);
        assert!(m.glyph('l').advance < m.glyph('m').advance);
        assert!(m.glyph(' ').advance > 0.0);
        assert!(m.glyph('l').lsb > 0.0);
        assert!(m.glyphs.contains_key(&'μ') && m.glyphs.contains_key(&'×'));
    }
}
