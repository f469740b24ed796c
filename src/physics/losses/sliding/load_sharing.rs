//! Load sharing between tooth pairs of a spur mesh (physics.md §7, seed 003 §4).
//!
//! Zones along the path of contact, in the direction of travel (A = start of engagement,
//! E = end, g = g_α, p = p_bt, 1 ≤ ε_α < 2): A..B double contact (B = E − p), B..D single
//! contact (D = A + p), D..E double contact. While one pair is in A..B the other is in D..E,
//! exactly one base pitch further on.

/// Load-sharing model for spur meshes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LoadSharing {
    /// 50:50 in double contact [std].
    #[default]
    Uniform,
    /// 1/3 : 2/3, the pair near its start of engagement (A..B) carries 1/3 [seed 003].
    /// (Seed 003 writes both "33:67" and "33:66"; the shares are taken as 1/3 and 2/3 so they sum to 1.)
    Share33_67,
    /// 0.45 : 0.55, the pair near its start of engagement carries 0.45 [seed 003].
    Share45_55,
    /// Linear ramp: 1/3 at A rising to 2/3 at B; mirrored 2/3 at D falling to 1/3 at E [spec §7].
    Ramp,
}

impl LoadSharing {
    /// Share of the normal load carried by one pair of a spur mesh with 1 ≤ ε_α < 2.
    ///
    /// `travel` is the pair's distance from the start of engagement along the direction of
    /// travel (0 at A, g at E), `g` the path length g_α, `p` the base pitch p_bt.
    /// Precondition (guaranteed by the table builder): p ≤ g < 2p, 0 ≤ travel ≤ g; a pair exactly
    /// on a zone boundary is classified as single contact.
    pub fn share(self, travel: f64, g: f64, p: f64) -> f64 {
        let double = g - p; // length of each double-contact zone
        if travel < double {
            // A..B: the pair that has just entered; its partner is at travel + p in D..E.
            match self {
                LoadSharing::Uniform => 0.5,
                LoadSharing::Share33_67 => 1.0 / 3.0,
                LoadSharing::Share45_55 => 0.45,
                LoadSharing::Ramp => 1.0 / 3.0 + (travel / double) / 3.0,
            }
        } else if travel > p {
            // D..E: the pair about to leave; its partner is at travel − p in A..B.
            match self {
                LoadSharing::Uniform => 0.5,
                LoadSharing::Share33_67 => 2.0 / 3.0,
                LoadSharing::Share45_55 => 0.55,
                LoadSharing::Ramp => 2.0 / 3.0 - ((travel - p) / double) / 3.0,
            }
        } else {
            1.0
        }
    }

    /// True if the model is defined for any contact ratio (only `Uniform`: 1/n for n pairs).
    pub fn supports_high_contact_ratio(self) -> bool {
        matches!(self, LoadSharing::Uniform)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [LoadSharing; 4] = [
        LoadSharing::Uniform,
        LoadSharing::Share33_67,
        LoadSharing::Share45_55,
        LoadSharing::Ramp,
    ];

    #[test]
    fn shares_of_simultaneous_pairs_sum_to_one() {
        let (g, p) = (1.63, 1.0);
        for m in ALL {
            for i in 0..200 {
                let t = (i as f64 + 0.5) / 200.0 * (g - p); // pair in A..B
                let sum = m.share(t, g, p) + m.share(t + p, g, p);
                assert!((sum - 1.0).abs() < 1e-14, "{m:?} t={t} sum={sum}");
            }
            // single contact carries everything
            assert_eq!(m.share(0.8, g, p), 1.0);
        }
    }

    #[test]
    fn entering_pair_carries_the_smaller_share() {
        let (g, p) = (1.5, 1.0);
        for m in [
            LoadSharing::Share33_67,
            LoadSharing::Share45_55,
            LoadSharing::Ramp,
        ] {
            let t = 0.1;
            assert!(m.share(t, g, p) < m.share(t + p, g, p), "{m:?}");
        }
    }

    #[test]
    fn ramp_end_values() {
        let (g, p) = (1.6, 1.0);
        let r = LoadSharing::Ramp;
        assert!((r.share(0.0, g, p) - 1.0 / 3.0).abs() < 1e-14); // at A
        assert!((r.share(0.6 - 1e-12, g, p) - 2.0 / 3.0).abs() < 1e-9); // just before B
        assert!((r.share(1.0 + 1e-12, g, p) - 2.0 / 3.0).abs() < 1e-9); // just after D
        assert!((r.share(1.6, g, p) - 1.0 / 3.0).abs() < 1e-14); // at E
    }
}
