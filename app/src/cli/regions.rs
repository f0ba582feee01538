//! The off pixels of an image as connected regions (8-neighbours), largest first, each with
//! its size, bounding box, whether it is only a one-pixel fringe along the reference's
//! silhouettes, and its most typical pixel: on the surface most of the region shows, the
//! one nearest the region's centre.

use super::judge::difference;

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Region {
    pub pixels: usize,
    /// (x0, row0, x1, row1), inclusive.
    pub bounds: (u32, u32, u32, u32),
    /// Every pixel of it lies on a silhouette of the reference (a 4-neighbour shows another
    /// surface or the background): the sampling of an edge, not a wrong surface.
    pub fringe: bool,
    /// (x, row) of the pixel whose story stands for the region.
    pub typical: (u32, u32),
}

/// The regions of pixels off between `mine` and `reference` (RGB bytes of a `w`×`h` image),
/// largest first (ties top to bottom); `nodes[i]` is the surface the reference's pixel `i`
/// shows (`u32::MAX` for the background).
pub fn regions(
    mine: &[u8],
    reference: &[u8],
    nodes: &[u32],
    (w, h): (u32, u32),
    tolerance: u8,
) -> Vec<Region> {
    let (wu, n) = (w as usize, w as usize * h as usize);
    let is_off: Vec<bool> = mine
        .chunks_exact(3)
        .zip(reference.chunks_exact(3))
        .map(|(p, q)| difference(p, q) > tolerance)
        .collect();
    if is_off.len() != n || nodes.len() != n {
        return Vec::new();
    }
    let silhouette = |i: usize| {
        let (x, y) = (i % wu, i / wu);
        let node = nodes[i];
        (x > 0 && nodes[i - 1] != node)
            || (x + 1 < wu && nodes[i + 1] != node)
            || (y > 0 && nodes[i - wu] != node)
            || (y + 1 < h as usize && nodes[i + wu] != node)
    };
    let mut seen = vec![false; n];
    let mut out = Vec::new();
    let mut stack = Vec::new();
    for start in 0..n {
        if !is_off[start] || seen[start] {
            continue;
        }
        seen[start] = true;
        stack.push(start);
        let mut members = Vec::new();
        while let Some(i) = stack.pop() {
            members.push(i);
            let (x, y) = ((i % wu) as i64, (i / wu) as i64);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                        continue;
                    }
                    let j = ny as usize * wu + nx as usize;
                    if is_off[j] && !seen[j] {
                        seen[j] = true;
                        stack.push(j);
                    }
                }
            }
        }
        out.push(region(&members, wu, nodes, silhouette));
    }
    out.sort_by_key(|r| (std::cmp::Reverse(r.pixels), r.bounds.1, r.bounds.0));
    out
}

fn region(
    members: &[usize],
    wu: usize,
    nodes: &[u32],
    silhouette: impl Fn(usize) -> bool,
) -> Region {
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    let (mut sx, mut sy) = (0f64, 0f64);
    for &i in members {
        let (x, y) = (i % wu, i / wu);
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        sx += x as f64;
        sy += y as f64;
    }
    let k = members.len() as f64;
    let (cx, cy) = (sx / k, sy / k);
    // The surface most of the region shows (the smallest id among equals, for repeatability).
    let mut counts: Vec<(u32, usize)> = Vec::new();
    for &i in members {
        match counts.iter_mut().find(|(n, _)| *n == nodes[i]) {
            Some(c) => c.1 += 1,
            None => counts.push((nodes[i], 1)),
        }
    }
    let common = counts
        .iter()
        .max_by_key(|(n, c)| (*c, std::cmp::Reverse(*n)))
        .map_or(u32::MAX, |(n, _)| *n);
    let typical = members
        .iter()
        .filter(|&&i| nodes[i] == common)
        .min_by(|&&a, &&b| {
            let d = |i: usize| {
                let (x, y) = ((i % wu) as f64, (i / wu) as f64);
                (x - cx).powi(2) + (y - cy).powi(2)
            };
            d(a).total_cmp(&d(b)).then(a.cmp(&b))
        })
        .copied()
        .unwrap_or(members[0]);
    Region {
        pixels: members.len(),
        bounds: (x0 as u32, y0 as u32, x1 as u32, y1 as u32),
        fringe: members.iter().all(|&i| silhouette(i)),
        typical: ((typical % wu) as u32, (typical / wu) as u32),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: usize, h: usize, off: &[(usize, usize)]) -> (Vec<u8>, Vec<u8>) {
        let reference = vec![100u8; w * h * 3];
        let mut mine = reference.clone();
        for &(x, y) in off {
            mine[(y * w + x) * 3] = 50;
        }
        (mine, reference)
    }

    #[test]
    fn off_pixels_group_into_regions_largest_first() {
        // A 3×2 block, and a lone pixel apart from it; diagonal neighbours join.
        let off = [
            (1, 1),
            (2, 1),
            (3, 1),
            (1, 2),
            (2, 2),
            (3, 2),
            (7, 5),
            (8, 6),
        ];
        let (mine, reference) = image(10, 8, &off);
        let nodes = vec![0u32; 80];
        let r = regions(&mine, &reference, &nodes, (10, 8), 2);
        assert_eq!(r.len(), 2);
        assert_eq!((r[0].pixels, r[0].bounds), (6, (1, 1, 3, 2)));
        assert_eq!(r[0].typical, (2, 1));
        assert!(!r[0].fringe);
        assert_eq!((r[1].pixels, r[1].bounds), (2, (7, 5, 8, 6)));
    }

    #[test]
    fn a_region_along_a_silhouette_is_a_fringe() {
        // The left half shows surface 0, the right half the background: column 4 and 5 are
        // the silhouette.
        let (w, h) = (10, 6);
        let nodes: Vec<u32> = (0..w * h)
            .map(|i| if i % w < 5 { 0 } else { u32::MAX })
            .collect();
        let edge: Vec<(usize, usize)> = (0..h).map(|y| (4, y)).collect();
        let (mine, reference) = image(w, h, &edge);
        let r = regions(&mine, &reference, &nodes, (w as u32, h as u32), 2);
        assert_eq!(r.len(), 1);
        assert!(r[0].fringe, "{r:?}");
        // One column further in is not on the silhouette: no fringe.
        let inner: Vec<(usize, usize)> = (0..h).map(|y| (3, y)).collect();
        let (mine, reference) = image(w, h, &inner);
        let r = regions(&mine, &reference, &nodes, (w as u32, h as u32), 2);
        assert!(!r[0].fringe, "{r:?}");
    }
}
