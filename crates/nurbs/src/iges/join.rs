//! Joining the members of a 102 composite curve into one NURBS: each split into rational
//! Bézier pieces, degree-elevated to the highest degree and concatenated with C⁰ joins.

use crate::vec3::distance;
use crate::NurbsCurve;

/// Homogeneous control points `[w x, w y, w z, w]`.
pub(super) type Homogeneous = [f64; 4];

/// The homogeneous form of the point `p` of weight `w`.
pub(super) fn to_homogeneous(p: [f64; 3], w: f64) -> Homogeneous {
    [p[0] * w, p[1] * w, p[2] * w, w]
}

/// The point a homogeneous control point stands for.
pub(super) fn from_homogeneous(h: Homogeneous) -> [f64; 3] {
    [h[0] / h[3], h[1] / h[3], h[2] / h[3]]
}

/// The rational Bézier pieces of a clamped curve, each with its parameter length: every
/// interior knot raised to multiplicity p, all in one pass (Piegl & Tiller A5.6), so that a
/// curve of n control points costs O(n p²), not a knot insertion of O(n) per knot.
fn bezier_pieces(c: &NurbsCurve) -> Result<Vec<(Vec<Homogeneous>, f64)>, String> {
    let p = c.degree;
    let n = c.control_points.len();
    let u = &c.knots;
    let clamped = u[..=p].iter().all(|&k| k == u[0]) && u[n..].iter().all(|&k| k == u[n + p]);
    if !clamped {
        return Err("a member with an unclamped knot vector cannot be joined".into());
    }
    if u[p + 1] == u[p] || u[n - 1] == u[n] {
        // the decomposition below needs ends of multiplicity exactly p + 1
        return Err(
            "a member with an end knot of multiplicity above p + 1 cannot be joined".into(),
        );
    }
    let pw: Vec<Homogeneous> = c
        .control_points
        .iter()
        .zip(&c.weights)
        .map(|(&x, &w)| to_homogeneous(x, w))
        .collect();
    let m = n + p; // index of the last knot
    let (mut a, mut b) = (p, p + 1);
    let mut piece = pw[..=p].to_vec();
    let mut alphas = vec![0.0; p];
    let mut out = Vec::new();
    while b < m {
        let first = b;
        while b < m && u[b + 1] == u[b] {
            b += 1;
        }
        let mult = b - first + 1;
        if b < m && mult > p {
            return Err(
                "a member with a knot of multiplicity above its degree cannot be joined".into(),
            );
        }
        let mut next = vec![[0.0; 4]; p + 1];
        if mult < p {
            // insert u[b] until its multiplicity is p, keeping the control points that
            // begin the next piece
            let numerator = u[b] - u[a];
            for j in (mult + 1..=p).rev() {
                alphas[j - mult - 1] = numerator / (u[a + j] - u[a]);
            }
            let r = p - mult;
            for j in 1..=r {
                let s = mult + j;
                for k in (s..=p).rev() {
                    let alpha = alphas[k - s];
                    for d in 0..4 {
                        piece[k][d] = alpha * piece[k][d] + (1.0 - alpha) * piece[k - 1][d];
                    }
                }
                next[r - j] = piece[p];
            }
        }
        out.push((std::mem::take(&mut piece), u[b] - u[a]));
        if b < m {
            for i in p - mult..=p {
                next[i] = pw[b - p + i];
            }
            piece = next;
            a = b;
            b += 1;
        }
    }
    Ok(out)
}

/// Degree elevation of a rational Bézier piece by one, in homogeneous coordinates:
/// `Q_i = i/(q+1) P_{i−1} + (1 − i/(q+1)) P_i`.
pub(super) fn elevate(piece: &[Homogeneous]) -> Vec<Homogeneous> {
    let q = piece.len() - 1;
    let mut out = Vec::with_capacity(q + 2);
    out.push(piece[0]);
    for i in 1..=q {
        let a = i as f64 / (q + 1) as f64;
        let mut h = [0.0; 4];
        for d in 0..4 {
            h[d] = a * piece[i - 1][d] + (1.0 - a) * piece[i][d];
        }
        out.push(h);
    }
    out.push(piece[q]);
    out
}

/// Joins curves end to start into one NURBS of the highest degree with C⁰ joins. Each member
/// keeps its parameter speed (its domain is shifted to follow the previous one); its weights
/// are rescaled so that the shared control point has one weight. Ends further apart than
/// `gap_tolerance` are an error.
pub(super) fn concatenate(parts: &[NurbsCurve], gap_tolerance: f64) -> Result<NurbsCurve, String> {
    if parts.len() == 1 {
        return Ok(parts[0].clone());
    }
    let p = parts.iter().map(|c| c.degree).max().unwrap_or(1);
    let mut t = parts.first().map_or(0.0, |c| c.domain().0);
    let mut knots = vec![t; p + 1];
    let mut points: Vec<Homogeneous> = Vec::new();
    for (k, part) in parts.iter().enumerate() {
        let mut pieces = bezier_pieces(part)?;
        for piece in &mut pieces {
            while piece.0.len() < p + 1 {
                piece.0 = elevate(&piece.0);
            }
        }
        if let Some(&last) = points.last() {
            let first = pieces[0].0[0];
            let gap = distance(from_homogeneous(last), from_homogeneous(first));
            if gap > gap_tolerance {
                return Err(format!(
                    "member {} starts {gap:e} away from where member {k} ends",
                    k + 1
                ));
            }
            let factor = last[3] / first[3];
            for piece in &mut pieces {
                for h in &mut piece.0 {
                    *h = h.map(|x| x * factor);
                }
            }
        }
        for (piece, length) in pieces {
            if points.is_empty() {
                points.extend_from_slice(&piece);
            } else {
                knots.extend(std::iter::repeat_n(t, p));
                points.extend_from_slice(&piece[1..]);
            }
            t += length;
        }
    }
    knots.extend(std::iter::repeat_n(t, p + 1));
    let weights = points.iter().map(|h| h[3]).collect();
    let control_points = points.into_iter().map(from_homogeneous).collect();
    NurbsCurve::new(p, knots, control_points, weights).map_err(|e| e.to_string())
}
