//! FLIP's colour spaces (D65): linear RGB <-> XYZ, YCxCz, CIELAB, the Hunt adjustment and the
//! HyAB distance (Andersson et al. 2020; constants of NVlabs/flip).

/// D65 reference white (X, Y, Z).
pub const WHITE: [f32; 3] = [0.950_428_55, 1.0, 1.088_900_4];
const INV_WHITE: [f32; 3] = [1.052_156_9, 1.0, 0.918_357_7];

const RGB2XYZ: [[f32; 3]; 3] = [
    [10_135_552.0 / 24_577_794.0, 8_788_810.0 / 24_577_794.0, 4_435_075.0 / 24_577_794.0],
    [2_613_072.0 / 12_288_897.0, 8_788_810.0 / 12_288_897.0, 887_015.0 / 12_288_897.0],
    [1_425_312.0 / 73_733_382.0, 8_788_810.0 / 73_733_382.0, 70_074_185.0 / 73_733_382.0],
];
const XYZ2RGB: [[f32; 3]; 3] = [
    [3.241_003_3, -1.537_398_9, -0.498_615_87],
    [-0.969_224_33, 1.875_930_1, 0.041_554_224],
    [0.055_639_423, -0.204_011_2, 1.057_148_9],
];

#[inline]
fn mat(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    [0, 1, 2].map(|r| m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2])
}

/// Linear sRGB to CIE XYZ.
#[inline]
pub fn linrgb_to_xyz(c: [f32; 3]) -> [f32; 3] {
    mat(&RGB2XYZ, c)
}

/// CIE XYZ to linear sRGB.
#[inline]
pub fn xyz_to_linrgb(c: [f32; 3]) -> [f32; 3] {
    mat(&XYZ2RGB, c)
}

/// XYZ to YCxCz (white-normalised; Y' = 116 Y - 16, Cx = 500 (X - Y), Cz = 200 (Y - Z)).
#[inline]
pub fn xyz_to_ycxcz(c: [f32; 3]) -> [f32; 3] {
    let [x, y, z] = [c[0] * INV_WHITE[0], c[1] * INV_WHITE[1], c[2] * INV_WHITE[2]];
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

/// YCxCz to XYZ.
#[inline]
pub fn ycxcz_to_xyz(c: [f32; 3]) -> [f32; 3] {
    let y = (c[0] + 16.0) / 116.0;
    let x = y + c[1] / 500.0;
    let z = y - c[2] / 200.0;
    [x * WHITE[0], y * WHITE[1], z * WHITE[2]]
}

/// Linear RGB to YCxCz.
#[inline]
pub fn linrgb_to_ycxcz(c: [f32; 3]) -> [f32; 3] {
    xyz_to_ycxcz(linrgb_to_xyz(c))
}

/// XYZ to CIELAB (D65).
#[inline]
pub fn xyz_to_lab(c: [f32; 3]) -> [f32; 3] {
    const DELTA: f32 = 6.0 / 29.0;
    let d3 = DELTA * DELTA * DELTA;
    let factor = 1.0 / (3.0 * DELTA * DELTA);
    let f = |t: f32| if t > d3 { t.cbrt() } else { factor * t + 4.0 / 29.0 };
    let [x, y, z] = [f(c[0] * INV_WHITE[0]), f(c[1] * INV_WHITE[1]), f(c[2] * INV_WHITE[2])];
    [116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)]
}

/// Hunt adjustment in CIELAB: (L, a, b) -> (L, 0.01 L a, 0.01 L b).
#[inline]
pub fn hunt(lab: [f32; 3]) -> [f32; 3] {
    [lab[0], 0.01 * lab[0] * lab[1], 0.01 * lab[0] * lab[2]]
}

/// HyAB distance |dL| + sqrt(da^2 + db^2).
#[inline]
pub fn hyab(p: [f32; 3], q: [f32; 3]) -> f32 {
    let (dl, da, db) = (p[0] - q[0], p[1] - q[1], p[2] - q[2]);
    dl.abs() + (da * da + db * db).sqrt()
}

/// Linear RGB to Hunt-adjusted CIELAB.
#[inline]
pub fn linrgb_to_hunt_lab(c: [f32; 3]) -> [f32; 3] {
    hunt(xyz_to_lab(linrgb_to_xyz(c)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_maps_to_lab_100() {
        let lab = xyz_to_lab(linrgb_to_xyz([1.0; 3]));
        assert!((lab[0] - 100.0).abs() < 1e-3 && lab[1].abs() < 1e-3 && lab[2].abs() < 1e-3);
    }

    #[test]
    fn ycxcz_round_trip() {
        let c = [0.2, 0.5, 0.9];
        let back = xyz_to_linrgb(ycxcz_to_xyz(linrgb_to_ycxcz(c)));
        for i in 0..3 {
            assert!((back[i] - c[i]).abs() < 1e-5);
        }
    }
}
