//! Ranking agreement between two score lists: Kendall's τ-b, the rank correlation that counts
//! concordant and discordant pairs and corrects for ties (Kendall 1945), as `scipy.stats.
//! kendalltau` computes it by default.

/// Kendall's τ-b of the pairs `(x[i], y[i])`: +1 when both orders agree, -1 when they are
/// reversed, 0 when unrelated. `None` with fewer than two pairs, or when either list is constant
/// (τ-b divides by the untied pairs of each list).
pub fn kendall_tau_b(x: &[f64], y: &[f64]) -> Option<f64> {
    let n = x.len().min(y.len());
    if n < 2 {
        return None;
    }
    let (mut concordant, mut discordant, mut tied_x, mut tied_y) = (0i64, 0i64, 0i64, 0i64);
    for i in 0..n {
        for j in i + 1..n {
            let dx = x[i].total_cmp(&x[j]) as i64;
            let dy = y[i].total_cmp(&y[j]) as i64;
            match (dx, dy) {
                (0, 0) => {}
                (0, _) => tied_x += 1,
                (_, 0) => tied_y += 1,
                _ if dx == dy => concordant += 1,
                _ => discordant += 1,
            }
        }
    }
    // n0 - n1 and n0 - n2: the pairs untied in x (resp. y), pairs tied in both excluded.
    let untied_x = (concordant + discordant + tied_y) as f64;
    let untied_y = (concordant + discordant + tied_x) as f64;
    if untied_x == 0.0 || untied_y == 0.0 {
        return None;
    }
    Some((concordant - discordant) as f64 / (untied_x * untied_y).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_reversed_and_known_values() {
        let x = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(kendall_tau_b(&x, &x), Some(1.0));
        let rev: Vec<f64> = x.iter().rev().copied().collect();
        assert_eq!(kendall_tau_b(&x, &rev), Some(-1.0));
        // scipy.stats.kendalltau([1, 2, 3, 4, 5], [3, 4, 1, 2, 5]).statistic == 0.2
        let t = kendall_tau_b(&x, &[3.0, 4.0, 1.0, 2.0, 5.0]).unwrap();
        assert!((t - 0.2).abs() < 1e-12, "{t}");
        // With ties, scipy: kendalltau([1, 1, 2, 3], [1, 2, 2, 3]).statistic
        // = 4 / sqrt(5 * 5) = 0.8
        let t = kendall_tau_b(&[1.0, 1.0, 2.0, 3.0], &[1.0, 2.0, 2.0, 3.0]).unwrap();
        assert!((t - 0.8).abs() < 1e-12, "{t}");
    }

    #[test]
    fn undefined_cases() {
        assert_eq!(kendall_tau_b(&[1.0], &[2.0]), None);
        assert_eq!(kendall_tau_b(&[1.0, 1.0, 1.0], &[1.0, 2.0, 3.0]), None);
    }
}
