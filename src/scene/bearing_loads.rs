//! Bearing loads from the gear forces: mesh forces (tangential, radial, axial) per unit input
//! torque of each gear state, their resultant on every member and planet, and the bearing
//! reactions by shaft statics. Precomputed once per scene; a sample scales them by its torque.
//!
//! Conventions (docs/physics.md §Bearing loads):
//! - each member and each planet has its own frame: z along its axis (positions from the model
//!   file), x–y transverse; forces are per unit input torque, signs from the kinematic torques
//!   of the state ([`Gearbox::mesh_torques`]: torque applied to gear 1 by one mesh);
//! - tangential force on gear 1 `F_t = T1/r_w1`, separating force `|F_t|·tan α_wt` pushing gear 1
//!   from the pitch point towards its axis, axial force `|F_t|·tan β_w·sign(T1)` (gear 1 taken
//!   right-handed; the model file has no helix hand), gear 2 gets the opposite force at the same
//!   point;
//! - fixed-axis pairs: gear 2 lies in the direction `(cos θ, sin θ)` from gear 1 with
//!   `sin θ = (h2 − h1)/a_w` from the axis heights of `[lubrication]` (same-height shafts side
//!   by side);
//! - planetary sets: one planet of each kind placed on the x axis (the first) or by the triangle
//!   of its centre distances (the others); with N ≥ 2 equally spaced planets the central members
//!   (suns, ring, carrier) carry no net radial or tilting load from the set, only the sum of the
//!   axial forces; planets are loaded by their own meshes and react on their pins;
//! - bearings: two per member or planet (static determinate; the `locating` one takes the axial
//!   load), or one, which then takes the resultant force and its pin/shaft takes the moment.

use crate::model::bearings::BearingMount;
use crate::model::gearbox::{GearMount, Gearbox};
use crate::physics::geometry::MeshKind;

/// A force at a point of a member's (or planet's) frame, per unit input torque.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PointForce {
    /// Point (x, y transverse offset from the axis; z axial position), m.
    pub at: [f64; 3],
    /// Force, N per N·m of input torque.
    pub force: [f64; 3],
}

/// Which body a force acts on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Body {
    /// A member (shaft, drum, carrier).
    Member(usize),
    /// A planet gear (its pin).
    Planet(usize),
}

/// The forces on every body and the bearing reactions in one gear state.
#[derive(Debug, Clone, Default)]
pub struct StateLoads {
    /// Applied (gear) forces per body.
    pub applied: Vec<(Body, PointForce)>,
    /// Reaction of each bearing on its body (force at the bearing's point), per unit input
    /// torque; planet bearings: one planet's.
    pub reactions: Vec<PointForce>,
    /// Moment taken by the shaft or pin where a body has a single bearing, per unit torque.
    pub pin_moments: Vec<(Body, [f64; 3])>,
}

/// Radial and axial magnitude of a reaction.
pub fn magnitudes(r: &PointForce) -> (f64, f64) {
    (r.force[0].hypot(r.force[1]), r.force[2].abs())
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(a: [f64; 3], k: f64) -> [f64; 3] {
    [a[0] * k, a[1] * k, a[2] * k]
}

/// Centre of every gear in its set's frame (central gears at the origin); fixed-axis gears at
/// the origin of their own member.
fn planet_centres(gb: &Gearbox) -> Vec<[f64; 2]> {
    let mut c: Vec<[f64; 2]> = vec![[0.0; 2]; gb.gears.len()];
    for (si, set) in gb.planetary_sets.iter().enumerate() {
        let planets: Vec<usize> = set
            .gears
            .iter()
            .copied()
            .filter(|&g| matches!(gb.gears[g].mount, GearMount::Planet { .. }))
            .collect();
        let orbit = |g: usize| {
            gb.meshes
                .iter()
                .filter(|m| m.set == Some(si) && (m.gear1 == g || m.gear2 == g))
                .find(|m| {
                    let other = if m.gear1 == g { m.gear2 } else { m.gear1 };
                    gb.gears[other].mount == GearMount::OnMember
                })
                .map_or(0.0, |m| m.geometry.a_w)
        };
        let mut placed: Vec<usize> = Vec::new();
        for &p in &planets {
            let r = orbit(p);
            // Angle from a placed planet it meshes with (triangle of the two orbits and their
            // centre distance); the first planet sits on the x axis.
            let mut angle: f64 = 0.0;
            for &q in &placed {
                if let Some(m) = gb.meshes.iter().find(|m| {
                    m.set == Some(si) && ((m.gear1 == p && m.gear2 == q) || (m.gear1 == q && m.gear2 == p))
                }) {
                    let rq = orbit(q);
                    let a = m.geometry.a_w;
                    let cos = ((r * r + rq * rq - a * a) / (2.0 * r * rq)).clamp(-1.0, 1.0);
                    angle = c[q][1].atan2(c[q][0]) + cos.acos();
                    break;
                }
            }
            c[p] = [r * angle.cos(), r * angle.sin()];
            placed.push(p);
        }
    }
    c
}

/// Forces on gear 1 and gear 2 of every mesh in state `si` per unit input torque (one planet's
/// share), each at the pitch point in the gear's own frame (origin on the gear's axis).
pub fn mesh_forces(gb: &Gearbox, si: usize) -> Vec<[PointForce; 2]> {
    let torques = gb.mesh_torques(si);
    let centres = planet_centres(gb);
    gb.meshes
        .iter()
        .zip(&torques)
        .map(|(m, &t1)| {
            let geo = &m.geometry;
            let (g1, g2) = (&gb.gears[m.gear1], &gb.gears[m.gear2]);
            // Direction from gear 1's axis to the pitch point.
            let e = match m.set {
                None => {
                    let s = ((g2.centre_height - g1.centre_height) / geo.a_w).clamp(-1.0, 1.0);
                    [(1.0 - s * s).sqrt(), s]
                }
                Some(_) => {
                    let (c1, c2) = (centres[m.gear1], centres[m.gear2]);
                    let d = match geo.kind {
                        MeshKind::External => [c2[0] - c1[0], c2[1] - c1[1]],
                        MeshKind::Internal => [c1[0] - c2[0], c1[1] - c2[1]],
                    };
                    let n = d[0].hypot(d[1]);
                    if n > 0.0 {
                        [d[0] / n, d[1] / n]
                    } else {
                        [1.0, 0.0]
                    }
                }
            };
            let t_dir = [-e[1], e[0]];
            let ft = t1 / geo.r_w1;
            let fr = ft.abs() * geo.alpha_wt.tan();
            let tan_beta_w = geo.beta_b.tan() / geo.alpha_wt.cos();
            let fa = ft * tan_beta_w;
            let f1 = [ft * t_dir[0] - fr * e[0], ft * t_dir[1] - fr * e[1], fa];
            // Pitch point from gear 2's axis: −r_w2·e (external) or +r_w2·e (internal).
            let s2 = match geo.kind {
                MeshKind::External => -geo.r_w2,
                MeshKind::Internal => geo.r_w2,
            };
            [
                PointForce {
                    at: [geo.r_w1 * e[0], geo.r_w1 * e[1], g1.position],
                    force: f1,
                },
                PointForce {
                    at: [s2 * e[0], s2 * e[1], g2.position],
                    force: scale(f1, -1.0),
                },
            ]
        })
        .collect()
}

/// The body a gear's forces load: its member, or the planet itself.
fn body_of(gb: &Gearbox, g: usize) -> Body {
    match gb.gears[g].mount {
        GearMount::OnMember => Body::Member(gb.gears[g].member),
        GearMount::Planet { .. } => Body::Planet(g),
    }
}

/// Applied forces and bearing reactions in state `si` per unit input torque.
pub fn state_loads(gb: &Gearbox, si: usize) -> StateLoads {
    let applied = applied_forces(gb, si);
    let mut reactions = vec![PointForce::default(); gb.bearings.len()];
    let mut pin_moments = Vec::new();
    // Bodies carrying bearings.
    let mut bodies: Vec<Body> = gb.bearings.iter().map(body_of_bearing).collect();
    bodies.sort_by_key(|b| match *b {
        Body::Member(i) => (0, i),
        Body::Planet(i) => (1, i),
    });
    bodies.dedup();
    for body in bodies {
        let idx: Vec<usize> = (0..gb.bearings.len())
            .filter(|&k| body_of_bearing(&gb.bearings[k]) == body)
            .collect();
        let mine: Vec<PointForce> = applied
            .iter()
            .filter(|(b, _)| *b == body)
            .map(|(_, f)| *f)
            .collect();
        match idx.as_slice() {
            [k] => {
                let (reaction, pin_moment) = single_bearing_reaction(gb.bearings[*k].position, &mine);
                reactions[*k] = reaction;
                pin_moments.push((body, pin_moment));
            }
            [a, b] => {
                let (ra, rb) = bearing_pair_reactions(&gb.bearings[*a], &gb.bearings[*b], &mine);
                reactions[*a] = ra;
                reactions[*b] = rb;
            }
            // More than two bearings on one body is rejected by the validation.
            _ => {}
        }
    }
    StateLoads {
        applied,
        reactions,
        pin_moments,
    }
}

/// The body a bearing carries.
fn body_of_bearing(b: &crate::model::bearings::Bearing) -> Body {
    match b.mount {
        BearingMount::Member { member, .. } => Body::Member(member),
        BearingMount::Planet { gear } => Body::Planet(gear),
    }
}

/// The mesh forces on every body in state `si` per unit input torque. A central gear of a set
/// with N ≥ 2 equally spaced planets: the transverse forces and the tilting moments of the N
/// meshes cancel; the axial forces add.
fn applied_forces(gb: &Gearbox, si: usize) -> Vec<(Body, PointForce)> {
    let forces = mesh_forces(gb, si);
    let mut applied: Vec<(Body, PointForce)> = Vec::new();
    for (m, pair) in gb.meshes.iter().zip(&forces) {
        for (k, g) in [(0, m.gear1), (1, m.gear2)] {
            let body = body_of(gb, g);
            let f = pair[k];
            match (m.set, body) {
                (Some(set), Body::Member(_)) if gb.planetary_sets[set].planets >= 2 => {
                    let n = gb.planetary_sets[set].planets as f64;
                    let axial = PointForce {
                        at: [0.0, 0.0, f.at[2]],
                        force: [0.0, 0.0, n * f.force[2]],
                    };
                    applied.push((body, axial));
                }
                _ => applied.push((body, f)),
            }
        }
    }
    applied
}

/// A body on one bearing at axial position `z` with the forces `mine`: the bearing's reaction,
/// and the moment the shaft or pin takes (that of the applied forces about the bearing point).
fn single_bearing_reaction(z: f64, mine: &[PointForce]) -> (PointForce, [f64; 3]) {
    let total = mine.iter().fold([0.0; 3], |s, f| add(s, f.force));
    let reaction = PointForce {
        at: [0.0, 0.0, z],
        force: scale(total, -1.0),
    };
    let m = mine.iter().fold([0.0; 3], |s, f| {
        add(s, cross([f.at[0], f.at[1], f.at[2] - z], f.force))
    });
    (reaction, [-m[0], -m[1], 0.0])
}

/// A body on the two bearings `a` and `b` with the forces `mine`: their reactions, the axial
/// load on the locating one (validation: exactly one of the two).
fn bearing_pair_reactions(
    a: &crate::model::bearings::Bearing,
    b: &crate::model::bearings::Bearing,
    mine: &[PointForce],
) -> (PointForce, PointForce) {
    let total = mine.iter().fold([0.0; 3], |s, f| add(s, f.force));
    let (za, zb) = (a.position, b.position);
    let l = zb - za;
    let m = mine.iter().fold([0.0; 3], |s, f| {
        add(s, cross([f.at[0], f.at[1], f.at[2] - za], f.force))
    });
    // Moments about A: M + (0,0,L) × R_B = 0 → R_B = (−M_y/L, M_x/L).
    let mut rb = [-m[1] / l, m[0] / l, 0.0];
    let mut ra = [-total[0] - rb[0], -total[1] - rb[1], 0.0];
    if b.locating && !a.locating {
        rb[2] = -total[2];
    } else {
        ra[2] = -total[2];
    }
    (
        PointForce {
            at: [0.0, 0.0, za],
            force: ra,
        },
        PointForce {
            at: [0.0, 0.0, zb],
            force: rb,
        },
    )
}

/// Largest residual of force and moment balance over every body with bearings (N and N·m per
/// unit input torque): applied forces + bearing reactions (+ pin moment for single bearings).
pub fn balance_residual(gb: &Gearbox, loads: &StateLoads) -> f64 {
    let body_of_bearing = |k: usize| body_of_bearing(&gb.bearings[k]);
    let mut worst: f64 = 0.0;
    for k in 0..gb.bearings.len() {
        let body = body_of_bearing(k);
        let mut f = [0.0; 3];
        let mut m = [0.0; 3];
        let items = loads
            .applied
            .iter()
            .filter(|(b, _)| *b == body)
            .map(|(_, p)| *p)
            .chain(
                (0..gb.bearings.len())
                    .filter(|&j| body_of_bearing(j) == body)
                    .map(|j| loads.reactions[j]),
            );
        for p in items {
            f = add(f, p.force);
            m = add(m, cross(p.at, p.force));
        }
        for (b, pm) in &loads.pin_moments {
            if *b == body {
                m = add(m, *pm);
            }
        }
        // The moment about the axis is the torque the member transmits: not a bearing load.
        worst = worst
            .max(f[0].abs())
            .max(f[1].abs())
            .max(f[2].abs())
            .max(m[0].abs())
            .max(m[1].abs());
    }
    worst
}
