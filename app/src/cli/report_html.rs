//! The batch report as one self-contained HTML page: per course line its verdicts, the
//! diagnosis, and for each image the student's, the reference and the heat map side by side,
//! inlined as base64 PNG (the page needs no other file and no network).

use std::fmt::Write as _;
use std::io::Cursor;
use std::path::Path;

use image::RgbImage;

use super::diff::Decoded;
use super::judge::Criterion;

/// An image's three pictures, PNG-encoded and in base64.
pub struct Pictures {
    pub mine: String,
    pub reference: String,
    pub heat: String,
    pub width: u32,
}

impl Pictures {
    pub fn new(d: &Decoded) -> Pictures {
        let (w, h) = d.mine.dimensions();
        let reference = RgbImage::from_raw(w, h, d.reference.clone());
        Pictures {
            mine: png_base64(&d.mine),
            reference: reference.as_ref().map(png_base64).unwrap_or_default(),
            heat: png_base64(&d.heat),
            width: w,
        }
    }
}

/// One image of a line: its verdict as the summary prints it.
pub struct ImageRow {
    pub verdict: String,
    pub ok: bool,
    /// `None` when the image was missing, unreadable or of the wrong size.
    pub pictures: Option<Pictures>,
    /// Why pictures that could be shown are not (too large to inline).
    pub note: Option<String>,
}

pub struct LineRow {
    /// The line's number in the commands file, from 1.
    pub number: usize,
    pub text: String,
    pub diagnosis: String,
    pub regions: String,
    pub images: Vec<ImageRow>,
    /// Why the line could not be judged (its flags, its scene).
    pub error: Option<String>,
}

fn png_base64(img: &RgbImage) -> String {
    let mut bytes = Vec::new();
    match img.write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png) {
        Ok(()) => base64(&bytes),
        Err(_) => String::new(),
    }
}

/// Standard base64 with padding (RFC 4648), for `data:` URLs.
pub fn base64(bytes: &[u8]) -> String {
    const ABC: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ABC[((n >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// Text for HTML: control characters escaped as in every other output (`\x1b`), then the
/// five special characters as entities.
pub fn escape_html(text: &str) -> String {
    let text = crate::io::escape_text(text);
    let mut out = String::with_capacity(text.len());
    for ch in text.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

const STYLE: &str = "body{font-family:system-ui,sans-serif;margin:1.5em;color:#222;background:#fafafa}\
h1{font-size:1.4em}h2{font-size:1.05em;margin:0}code,pre{font-family:ui-monospace,monospace;font-size:.85em}\
pre{white-space:pre-wrap;background:#f0f0f0;padding:.5em;margin:.4em 0}\
section{background:#fff;border:1px solid #ddd;border-left:6px solid #bbb;padding:.8em 1em;margin:1em 0}\
section.ok{border-left-color:#2a2}section.bad{border-left-color:#d33}section.err{border-left-color:#e90}\
.ok b{color:#2a2}.bad b{color:#d33}.verdict{margin:.2em 0}\
figure{display:inline-block;margin:.3em .6em .3em 0;text-align:center}\
figcaption{font-size:.8em;color:#555}img{image-rendering:pixelated;border:1px solid #ccc}\
table.sum{border-collapse:collapse}table.sum td{padding:.1em .6em;border-bottom:1px solid #eee}table.sum td:first-child{white-space:nowrap}";

/// The whole page.
pub fn report_html(
    commands: &Path,
    images: &Path,
    scenes: &Path,
    c: &Criterion,
    warnings: &[String],
    rows: &[LineRow],
) -> String {
    let e = |p: &Path| escape_html(&p.display().to_string());
    let (total, ok) = rows
        .iter()
        .flat_map(|r| &r.images)
        .fold((0, 0), |(t, k), i| (t + 1, k + usize::from(i.ok)));
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>tracelab diff: {}</title><style>{STYLE}</style></head><body>\n\
         <h1>tracelab diff: {ok} of {total} images match</h1>\n\
         <p>Commands <code>{}</code>, images from <code>{}</code>, scenes from <code>{}</code>. \
         A pixel is off when a channel differs by more than {}/255; an image matches when \
         {} of its pixels are off. Heat maps: pixels not off in dim grey, the others from red \
         (just over) to yellow (far off).</p>\n",
        e(commands),
        e(commands),
        e(images),
        e(scenes),
        c.tolerance,
        escape_html(&c.limit()),
    );
    for w in warnings {
        let _ = writeln!(h, "<p class=\"warn\">warning: {}</p>", escape_html(w));
    }
    h.push_str("<table class=\"sum\">\n");
    for r in rows {
        for i in &r.images {
            let _ = writeln!(
                h,
                "<tr class=\"{}\"><td><a href=\"#line{}\">line {}</a></td><td><b>{}</b></td><td>{}</td></tr>",
                if i.ok { "ok" } else { "bad" },
                r.number,
                r.number,
                if i.ok { "matches" } else { "differs" },
                escape_html(&i.verdict)
            );
        }
        if let Some(err) = &r.error {
            let _ = writeln!(
                h,
                "<tr class=\"bad\"><td><a href=\"#line{}\">line {}</a></td><td><b>error</b></td><td>{}</td></tr>",
                r.number,
                r.number,
                escape_html(err)
            );
        }
    }
    h.push_str("</table>\n");
    for r in rows {
        let class = if r.error.is_some() {
            "err"
        } else if r.images.iter().all(|i| i.ok) {
            "ok"
        } else {
            "bad"
        };
        let _ = writeln!(
            h,
            "<section id=\"line{}\" class=\"{class}\"><h2>line {}: <code>{}</code></h2>",
            r.number,
            r.number,
            escape_html(&r.text)
        );
        if let Some(err) = &r.error {
            let _ = writeln!(h, "<p>not judged: {}</p>", escape_html(err));
        }
        if !r.diagnosis.is_empty() {
            let _ = writeln!(h, "<pre>{}</pre>", escape_html(&r.diagnosis));
        }
        for i in &r.images {
            let _ = writeln!(
                h,
                "<p class=\"verdict {}\"><b>{}</b> {}</p>",
                if i.ok { "ok" } else { "bad" },
                if i.ok { "✓" } else { "✗" },
                escape_html(&i.verdict)
            );
            if let Some(n) = &i.note {
                let _ = writeln!(h, "<p>{}</p>", escape_html(n));
            }
            if let Some(p) = &i.pictures {
                // Small images shown at least 200 px wide, pixels kept sharp.
                let w = p.width.clamp(200, 400);
                for (caption, data) in [
                    ("yours", &p.mine),
                    ("reference", &p.reference),
                    ("heat map", &p.heat),
                ] {
                    let _ = writeln!(
                        h,
                        "<figure><img width=\"{w}\" alt=\"{caption}\" src=\"data:image/png;base64,{data}\"><figcaption>{caption}</figcaption></figure>"
                    );
                }
            }
        }
        if !r.regions.is_empty() {
            let _ = writeln!(
                h,
                "<details><summary>regions of off pixels</summary><pre>{}</pre></details>",
                escape_html(&r.regions)
            );
        }
        h.push_str("</section>\n");
    }
    h.push_str("</body></html>\n");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded, "{plain}");
        }
        assert_eq!(base64(&[0xff, 0xfe, 0x00]), "//4A");
    }

    #[test]
    fn html_escapes_markup_and_control_bytes() {
        assert_eq!(
            escape_html("<a href=\"x\">&'\u{1b}[31m\n"),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;\\x1b[31m\n"
        );
    }
}
