//! Assignment 7 on the command line: the sampler, the filter, the seed and the course's two
//! pictures (`-render_samples`, `-render_filter`), however they were spelled (the course's
//! flags or `tracelab render`'s), checked into core's [`Sampler`] and [`Filter`].

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use tracelab_core::render::film::{filter_picture_size, samples_picture_size};
use tracelab_core::render::{
    Cancel, DEFAULT_SEED, Film, FilmError, Filter, Picture, Sampler, SamplerKind, check_film,
    filter_picture,
};
use tracelab_core::{CompiledScene, Frame, RenderSettings, View};

use super::progress::Watcher;
use super::values::{parse_f32, parse_u32};
use crate::exit::usage;

/// The flags as given, each with the spelling that set it (for messages).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Supersample {
    pub sampler: Option<(SamplerKind, u32, String)>,
    pub filter: Option<(Filter, String)>,
    pub seed: Option<(u64, String)>,
    /// `-render_samples FILE ZOOM`, with its spelling.
    pub render_samples: Option<(PathBuf, u32, String)>,
    /// `-render_filter FILE ZOOM`, with its spelling.
    pub render_filter: Option<(PathBuf, u32, String)>,
}

/// The checked settings of a job that uses assignment 7.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resolved {
    pub sampler: Sampler,
    pub filter: Filter,
}

impl Supersample {
    /// Whether any of assignment 7's flags was given.
    pub fn is_set(&self) -> bool {
        self.sampler.is_some()
            || self.filter.is_some()
            || self.seed.is_some()
            || self.render_samples.is_some()
            || self.render_filter.is_some()
    }

    /// Whether the colour image goes through the film (samples and a filter) rather than
    /// the one-ray-a-pixel renderer (the same image for one centred sample and no filter).
    pub fn filters_the_output(&self) -> bool {
        self.sampler.is_some() || self.filter.is_some()
    }

    /// `FLAG N`: a sampler of N samples a pixel; a second sampler flag is refused.
    pub fn set_sampler(
        &mut self,
        kind: SamplerKind,
        value: &OsStr,
        flag: &str,
    ) -> anyhow::Result<()> {
        let n = parse_u32(value, flag)?;
        if let Some((_, _, first)) = &self.sampler {
            return Err(usage(format!(
                "{flag}: {first} already chose the sampler; give one of -uniform_samples, \
                 -random_samples, -jittered_samples"
            )));
        }
        Sampler::new(kind, n, DEFAULT_SEED).map_err(|e| usage(format!("{flag} {n}: {e}")))?;
        self.sampler = Some((kind, n, flag.to_string()));
        Ok(())
    }

    /// `FLAG R`: a filter; a second filter flag is refused.
    pub fn set_filter(
        &mut self,
        make: fn(f32) -> Result<Filter, tracelab_core::render::FilterError>,
        value: &OsStr,
        flag: &str,
    ) -> anyhow::Result<()> {
        let v = parse_f32(value, flag)?;
        if let Some((_, first)) = &self.filter {
            return Err(usage(format!(
                "{flag}: {first} already chose the filter; give one of -box_filter, \
                 -tent_filter, -gaussian_filter"
            )));
        }
        let f = make(v).map_err(|e| usage(format!("{flag}: {e}")))?;
        self.filter = Some((f, flag.to_string()));
        Ok(())
    }

    /// `FLAG N`: the seed of random and jittered sampling, any whole number from 0 to 2⁶⁴−1.
    pub fn set_seed(&mut self, value: &OsStr, flag: &str) -> anyhow::Result<()> {
        let seed = value
            .to_str()
            .and_then(|t| t.parse::<u64>().ok())
            .ok_or_else(|| {
                usage(format!(
                    "{flag}: expected a whole number from 0 to {}, found \"{}\"",
                    u64::MAX,
                    value.display()
                ))
            })?;
        self.seed = Some((seed, flag.to_string()));
        Ok(())
    }

    /// `FLAG FILE ZOOM` for either picture.
    pub fn picture(
        file: &OsStr,
        zoom: &OsStr,
        flag: &str,
    ) -> anyhow::Result<(PathBuf, u32, String)> {
        let zoom = parse_u32(zoom, &format!("{flag} zoom"))?;
        Ok((PathBuf::from(file), zoom, flag.to_string()))
    }

    /// The files the pictures are written to.
    pub fn outputs(&self) -> impl Iterator<Item = &Path> {
        self.render_samples
            .iter()
            .chain(&self.render_filter)
            .map(|(p, _, _)| p.as_path())
    }

    /// Every check that needs no scene: the seed's sampler, the caps on samples, filter
    /// work and picture sizes, and the combinations tracelab does not make. `plain` names
    /// the other outputs given (normals, depth), `grid_view` whether `-visualize_grid` is on,
    /// `stats` whether `-stats` is.
    pub fn resolve(
        &self,
        width: u32,
        height: u32,
        others: &[&str],
        stats: Option<&str>,
    ) -> anyhow::Result<Resolved> {
        let seed = self.seed.as_ref().map_or(DEFAULT_SEED, |s| s.0);
        let sampler = match &self.sampler {
            Some((kind, n, flag)) => {
                Sampler::new(*kind, *n, seed).map_err(|e| usage(format!("{flag} {n}: {e}")))?
            }
            None => Sampler::default(),
        };
        if let Some((_, seed_flag)) = &self.seed {
            let random = matches!(
                self.sampler,
                Some((SamplerKind::Random | SamplerKind::Jittered, _, _))
            );
            if !random {
                return Err(usage(format!(
                    "{seed_flag} only changes random and jittered sampling: give \
                     -random_samples N or -jittered_samples N (--sampler random|jittered) too"
                )));
            }
        }
        let filter = self.filter.as_ref().map_or_else(Filter::default, |f| f.0);
        if self.is_set() {
            let first = self.first_flag();
            if let Some(other) = others.first() {
                return Err(usage(format!(
                    "{other} with {first}: normal and depth images of a supersampled render \
                     are not implemented; render them in a separate command"
                )));
            }
            if let Some(stats) = stats {
                return Err(usage(format!(
                    "{stats} with {first}: the statistics count one eye ray a pixel and are not \
                     implemented for supersampling; run the line without {stats}"
                )));
            }
        }
        let name = |o: &Option<(Filter, String)>, s: &Option<(SamplerKind, u32, String)>| {
            let mut v: Vec<String> = Vec::new();
            if let Some((_, _, f)) = s {
                v.push(f.clone());
            }
            if let Some((_, f)) = o {
                v.push(f.clone());
            }
            v.join(" with ")
        };
        if self.filters_the_output() || self.render_samples.is_some() {
            check_film(width, height, &sampler, &filter)
                .map_err(|e| usage(format!("{}: {e}", name(&self.filter, &self.sampler))))?;
        }
        if let Some((_, zoom, flag)) = &self.render_samples {
            samples_picture_size(width, height, *zoom)
                .map_err(|e| usage(format!("{flag} zoom {zoom}: {e}")))?;
        }
        if let Some((_, zoom, flag)) = &self.render_filter {
            filter_picture_size(width, height, *zoom)
                .map_err(|e| usage(format!("{flag} zoom {zoom}: {e}")))?;
        }
        Ok(Resolved { sampler, filter })
    }

    fn first_flag(&self) -> String {
        self.sampler
            .as_ref()
            .map(|s| s.2.clone())
            .or_else(|| self.filter.as_ref().map(|f| f.1.clone()))
            .or_else(|| self.render_samples.as_ref().map(|r| r.2.clone()))
            .or_else(|| self.render_filter.as_ref().map(|r| r.2.clone()))
            .or_else(|| self.seed.as_ref().map(|s| s.1.clone()))
            .unwrap_or_default()
    }

    /// Refuses the pictures where a command writes no file but its verdict (`diff`).
    pub fn refuse_pictures(&self, command: &str) -> anyhow::Result<()> {
        match self.render_samples.iter().chain(&self.render_filter).next() {
            Some((_, _, flag)) => Err(usage(format!(
                "{command} compares the colour image a line writes; {flag} writes a picture of \
                 the samples or the filter, which {command} does not judge: run that line by itself"
            ))),
            None => Ok(()),
        }
    }
}

/// A film error as the command line reports it: running out of memory is an error (exit 1),
/// anything else was refused by a cap (a usage error).
pub fn film_error(e: FilmError) -> anyhow::Error {
    match e {
        FilmError::OutOfMemory(m) => anyhow::anyhow!("not enough memory for the samples: {m}"),
        other => usage(other.to_string()),
    }
}

/// The film's bars: share of the rows started.
const FILM_PROGRESS: &str =
    "tracing samples [{bar:30}] {percent:>3}% ({elapsed}, about {eta} left)";
const FILTER_PROGRESS: &str =
    "filtering       [{bar:30}] {percent:>3}% ({elapsed}, about {eta} left)";

/// Counts the rows the film has started: the film asks its `Cancel` once before each row,
/// so the count is the progress, and nothing in core needs to know about bars.
#[derive(Default)]
struct RowCounter(AtomicU64);

impl Cancel for RowCounter {
    type Stop = std::convert::Infallible;
    fn stop(&self) -> Option<std::convert::Infallible> {
        self.0.fetch_add(1, Ordering::Relaxed);
        None
    }
}

/// The supersampled colour image, with a bar on a terminal once it takes over a second
/// (36 samples a pixel trace 36 times the rays of a plain render).
pub fn film_for(
    compiled: &CompiledScene,
    settings: &RenderSettings,
    r: &Resolved,
) -> anyhow::Result<Film> {
    settings.secondary.check_bounded(compiled).map_err(usage)?;
    let rows = Arc::new(RowCounter::default());
    let watched = rows.clone();
    let bar = Watcher::on_stderr(FILM_PROGRESS, u64::from(settings.height), move || {
        watched.0.load(Ordering::Relaxed)
    });
    let Ok(film) = Film::render_until(compiled, settings, r.sampler, &*rows);
    bar.finish();
    film.map_err(film_error)
}

/// The film filtered into the colour image, with a bar on a terminal once it takes over a
/// second (a wide Gaussian over many samples takes minutes).
pub fn filtered_frame(film: &Film, filter: &Filter) -> anyhow::Result<Frame> {
    let rows = Arc::new(RowCounter::default());
    let watched = rows.clone();
    let bar = Watcher::on_stderr(FILTER_PROGRESS, u64::from(film.height), move || {
        watched.0.load(Ordering::Relaxed)
    });
    let Ok(frame) = film.frame_until(filter, &*rows);
    bar.finish();
    frame.map_err(film_error)
}

/// Writes a picture through the output policy's atomic write.
pub fn write_picture(pic: &Picture, path: &Path) -> anyhow::Result<()> {
    let mut frame = Frame::try_new(pic.width, pic.height)
        .map_err(|e| anyhow::anyhow!("not enough memory for {}: {e}", path.display()))?;
    for (s, c) in frame.samples.iter_mut().zip(pic.rgb.chunks_exact(3)) {
        s.color = [c[0], c[1], c[2]];
    }
    crate::io::write_image(&frame, View::Color, (0.0, 1.0), path).map_err(anyhow::Error::msg)
}

/// The pictures a job asks for, from its film (`-render_samples`) and its filter.
pub fn write_pictures(
    s: &Supersample,
    r: &Resolved,
    film: Option<&Film>,
    (width, height): (u32, u32),
) -> anyhow::Result<()> {
    if let Some((path, zoom, _)) = &s.render_samples {
        let Some(film) = film else {
            anyhow::bail!("internal: -render_samples without a film");
        };
        write_picture(&film.samples_picture(*zoom).map_err(film_error)?, path)?;
    }
    if let Some((path, zoom, _)) = &s.render_filter {
        write_picture(
            &filter_picture(width, height, *zoom, &r.filter).map_err(film_error)?,
            path,
        )?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use tracelab_core::{MeshCache, parse_scene};

    use super::*;

    /// The film's bar reads the rows the film has started: after a film of 7 rows, 7 (a
    /// counter never asked would leave the bar at 0 for the whole render).
    #[test]
    fn the_row_counter_counts_every_row_of_the_film() {
        let text = "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 5 }
            Background { color 0 0 1 }
            Materials { numMaterials 1 Material { diffuseColor 1 0 0 } }
            Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 1 } }";
        let scene = parse_scene(text.as_bytes(), "t", None, &mut MeshCache::new())
            .scene
            .expect("parses");
        let compiled = CompiledScene::new(&scene);
        let settings = RenderSettings::new(5, 7);
        let sampler = Sampler::new(SamplerKind::Uniform, 4, DEFAULT_SEED).expect("sampler");
        let rows = RowCounter::default();
        let Ok(film) = Film::render_until(&compiled, &settings, sampler, &rows);
        assert!(film.is_ok());
        assert_eq!(rows.0.load(Ordering::Relaxed), 7);
    }
}
