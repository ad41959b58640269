//! Daylight as Mitsuba 0.6 renders it (`sunsky`, `sky` and `sun`, src/emitters/): the
//! Hosek-Wilkie sky in its RGB form and Preetham's sun, rasterised into a latitude-longitude
//! environment map.
//!
//! Directions use Mitsuba's spherical coordinates in the light's frame, +y up: a zenith angle
//! θ and an azimuth φ with d = (sin φ sin θ, cos θ, -cos φ sin θ) (the envmap's mapping, see
//! [`crate::envmap`]).
//!
//! - Sky (Hosek and Wilkie 2012, RGB coefficients): per channel c, with γ the angle to the
//!   sun, L_c(θ, γ) = F(θ, γ; A..I) · L_M,c / 106.856980 · sky_scale, zero below the horizon
//!   (θ / stretch ≥ π/2), where F = (1 + A e^{B / (cos θ + 0.01)}) (C + D e^{Eγ} +
//!   F cos²γ + G χ(H, γ) + I √cos θ) and χ(g, γ) = (1 + cos²γ) / (1 + g² - 2g cos γ)^{3/2}. The
//!   coefficients and L_M are quintic Bézier blends over the solar elevation (parameter
//!   (elevation / (π/2))^{1/3}) of the tabulated control points, linear in turbidity and in
//!   the ground albedo of that channel. The divisor is Mitsuba 0.6's (the sum of its CIE ȳ).
//! - Sun (Preetham, Shirley and Smits 1999, appendix A.2): the extraterrestrial solar
//!   spectrum attenuated along the relative optical mass m(θ_s) by Rayleigh scattering,
//!   aerosols (Ångström's β = 0.04608 T - 0.04586, α = 1.3), ozone (0.35 cm), mixed gases
//!   and water vapour (2 cm), every 5 nm from 350 to 800 nm, reduced to RGB as Mitsuba 0.6
//!   reduces spectra ([`spectrum::to_srgb_v06`]), times sun_scale. The disc has the angular
//!   radius 0.2679° · sun_radius_scale and keeps the power of the true sun (0.2679°):
//!   scaling the radius dims it.
//! - Rasterisation: the sky at the centre of every texel; the sun splatted with a (0, 2)
//!   sequence of directions uniform in its cone (at least 1000 per texel it covers), each
//!   carrying L Ω_sun / (N · texel solid angle), as Mitsuba does, so that the map's integral
//!   of the sun is the sun's power whatever the resolution.
//!
//! The sun's position is given as a direction or computed from a date, a time and a place on
//! Earth (Blanco-Muriel et al., "Computing the Solar Vector", Solar Energy 70(5), 2001),
//! with Mitsuba 0.6's defaults (Tokyo, 10 July 2010, 15:00).
//!
//! The tables are in `core/data/sky/` with their sources.

use crate::spectrum;
use crate::texture::Bitmap;
use glam::{DVec3, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::LazyLock;

/// Half the sun's apparent angular diameter (degrees), Mitsuba's `SUN_APP_RADIUS / 2`.
const SUN_HALF_APERTURE_DEG: f64 = 0.5358 * 0.5;
/// Mitsuba 0.6 divides the RGB sky model by this (the sum of its CIE ȳ table).
const SKY_RGB_NORMALISATION: f64 = 106.856980;

/// A zenith angle θ from +y and an azimuth φ (radians), Mitsuba's `SphericalCoordinates`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spherical {
    pub theta: f64,
    pub phi: f64,
}

impl Spherical {
    /// Mitsuba's `toSphere`.
    pub fn direction(self) -> DVec3 {
        let (st, ct) = self.theta.sin_cos();
        let (sp, cp) = self.phi.sin_cos();
        DVec3::new(sp * st, ct, -cp * st)
    }

    /// Mitsuba's `fromSphere` of a unit vector.
    pub fn of(d: DVec3) -> Spherical {
        let mut phi = d.x.atan2(-d.z);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        Spherical {
            theta: d.y.clamp(-1.0, 1.0).acos(),
            phi,
        }
    }
}

/// The parameters that place the sun by date, time and place (instead of a direction), in
/// Mitsuba 0.6's names and the TOML light's.
pub const DATE_KEYS: [&str; 9] = [
    "year",
    "month",
    "day",
    "hour",
    "minute",
    "second",
    "latitude",
    "longitude",
    "timezone",
];

/// A date and a time of day in the time zone of a [`Place`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DateTime {
    pub year: i32,
    pub month: i32,
    pub day: i32,
    pub hour: f64,
    pub minute: f64,
    pub second: f64,
}

impl Default for DateTime {
    /// Mitsuba 0.6's default: 10 July 2010, 15:00.
    fn default() -> DateTime {
        DateTime {
            year: 2010,
            month: 7,
            day: 10,
            hour: 15.0,
            minute: 0.0,
            second: 0.0,
        }
    }
}

/// Degrees of latitude (north) and longitude (east), and hours ahead of UTC.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Place {
    pub latitude: f64,
    pub longitude: f64,
    pub timezone: f64,
}

impl Default for Place {
    /// Mitsuba 0.6's default: Tokyo.
    fn default() -> Place {
        Place {
            latitude: 35.6894,
            longitude: 139.6917,
            timezone: 9.0,
        }
    }
}

/// The sun's zenith angle and azimuth (from north, towards east) seen from `place` at `when`
/// (Blanco-Muriel et al. 2001, with the parallax correction), in the frame where +y is the
/// zenith.
pub fn sun_position(when: &DateTime, place: &Place) -> Spherical {
    const EARTH_MEAN_RADIUS_KM: f64 = 6371.01;
    const ASTRONOMICAL_UNIT_KM: f64 = 149597890.0;
    let dec_hours = when.hour - place.timezone + (when.minute + when.second / 60.0) / 60.0;
    // The Julian day, in integer arithmetic as the paper writes it.
    let aux1 = (when.month - 14) / 12;
    let aux2 = (1461 * (when.year + 4800 + aux1)) / 4 + (367 * (when.month - 2 - 12 * aux1)) / 12
        - (3 * ((when.year + 4900 + aux1) / 100)) / 4
        + when.day
        - 32075;
    let julian_date = aux2 as f64 - 0.5 + dec_hours / 24.0;
    let n = julian_date - 2451545.0;

    let omega = 2.1429 - 0.0010394594 * n;
    let mean_longitude = 4.8950630 + 0.017202791698 * n;
    let anomaly = 6.2400600 + 0.0172019699 * n;
    let ecliptic_longitude =
        mean_longitude + 0.03341607 * anomaly.sin() + 0.00034894 * (2.0 * anomaly).sin()
            - 0.0001134
            - 0.0000203 * omega.sin();
    let ecliptic_obliquity = 0.4090928 - 6.2140e-9 * n + 0.0000396 * omega.cos();

    let sin_longitude = ecliptic_longitude.sin();
    let mut right_ascension =
        (ecliptic_obliquity.cos() * sin_longitude).atan2(ecliptic_longitude.cos());
    if right_ascension < 0.0 {
        right_ascension += 2.0 * PI;
    }
    let declination = (ecliptic_obliquity.sin() * sin_longitude).asin();

    let gmst = 6.6974243242 + 0.0657098283 * n + dec_hours;
    let lmst = ((gmst * 15.0 + place.longitude) as f32).to_radians() as f64;
    let latitude = place.latitude.to_radians();
    let hour_angle = lmst - right_ascension;
    let mut zenith = (latitude.cos() * hour_angle.cos() * declination.cos()
        + declination.sin() * latitude.sin())
    .acos();
    let mut azimuth = (-hour_angle.sin())
        .atan2(declination.tan() * latitude.cos() - latitude.sin() * hour_angle.cos());
    if azimuth < 0.0 {
        azimuth += 2.0 * PI;
    }
    zenith += (EARTH_MEAN_RADIUS_KM / ASTRONOMICAL_UNIT_KM) * zenith.sin();
    Spherical {
        theta: zenith,
        phi: azimuth,
    }
}

/// Preetham's tables: wavelength (nm) and value, linear between, zero outside.
struct Table {
    wavelengths: Vec<f64>,
    values: Vec<f64>,
}

impl Table {
    fn eval(&self, lambda: f64) -> f64 {
        let w = &self.wavelengths;
        if lambda < w[0] || lambda > w[w.len() - 1] {
            return 0.0;
        }
        let i = w.partition_point(|&x| x <= lambda).clamp(1, w.len() - 1);
        let t = (lambda - w[i - 1]) / (w[i] - w[i - 1]);
        self.values[i - 1] * (1.0 - t) + self.values[i] * t
    }
}

struct SunTables {
    k_o: Table,
    k_g: Table,
    k_wa: Table,
    solar: Table,
}

static SUN_TABLES: LazyLock<SunTables> = LazyLock::new(|| {
    let text = include_str!("../data/sky/preetham_sun.txt");
    let mut tables: Vec<(String, Table)> = Vec::new();
    for line in text.lines() {
        if let Some(name) = line.strip_prefix("## ") {
            let name = name.split(':').next().unwrap_or(name).to_string();
            tables.push((
                name,
                Table {
                    wavelengths: Vec::new(),
                    values: Vec::new(),
                },
            ));
        } else if !line.starts_with('#') && !line.trim().is_empty() {
            let x: Vec<f64> = line
                .split_whitespace()
                .map(|x| {
                    x.parse()
                        .expect("core/data/sky/preetham_sun.txt is numbers")
                })
                .collect();
            let (_, t) = tables.last_mut().expect("a table heading first");
            t.wavelengths.push(x[0]);
            t.values.push(x[1]);
        }
    }
    let mut take = |name: &str| {
        let i = tables
            .iter()
            .position(|(n, _)| n == name)
            .expect("preetham_sun.txt has the table");
        tables.swap_remove(i).1
    };
    SunTables {
        k_o: take("k_o"),
        k_g: take("k_g"),
        k_wa: take("k_wa"),
        solar: take("solar"),
    }
});

/// The radiance (linear sRGB, W m⁻² sr⁻¹) of the sun's disc seen at the zenith angle `theta`
/// through an atmosphere of the given turbidity (Preetham et al. 1999), reduced to RGB as
/// Mitsuba 0.6 does.
pub fn sun_radiance(theta: f64, turbidity: f64) -> DVec3 {
    let t = &*SUN_TABLES;
    let beta = 0.04608365822050 * turbidity - 0.04586025928522;
    // The relative optical mass (Kasten's formula, the zenith angle in degrees).
    let m = 1.0 / (theta.cos() + 0.15 * (93.885 - theta.to_degrees()).powf(-1.253));
    let (alpha, ozone_cm, water_cm) = (1.3, 0.35, 2.0);
    let attenuated = |lambda: f64| {
        let um = lambda / 1000.0;
        let tau_r = (-m * 0.008735 * um.powf(-4.08)).exp();
        let tau_a = (-m * beta * um.powf(-alpha)).exp();
        let tau_o = (-m * t.k_o.eval(lambda) * ozone_cm).exp();
        let k_g = t.k_g.eval(lambda);
        let tau_g = (-1.41 * k_g * m / (1.0 + 118.93 * k_g * m).powf(0.45)).exp();
        let k_wa = t.k_wa.eval(lambda);
        let tau_wa =
            (-0.2385 * k_wa * water_cm * m / (1.0 + 20.07 * k_wa * water_cm * m).powf(0.45)).exp();
        t.solar.eval(lambda) * tau_r * tau_a * tau_o * tau_g * tau_wa
    };
    // Mitsuba samples the product every 5 nm and interpolates linearly between the samples.
    let knots: Vec<f64> = (0..91).map(|i| 350.0 + 5.0 * i as f64).collect();
    let samples: Vec<f64> = knots.iter().map(|&l| attenuated(l)).collect();
    let table = Table {
        wavelengths: knots.clone(),
        values: samples,
    };
    spectrum::to_srgb_v06(|l| table.eval(l), &knots).max(DVec3::ZERO)
}

/// The RGB Hosek-Wilkie tables: for each channel, 2 albedos x 10 turbidities x 6 control
/// points x 9 coefficients, then 2 x 10 x 6 radiances.
struct SkyTables {
    config: [Vec<f64>; 3],
    radiance: [Vec<f64>; 3],
}

static SKY_TABLES: LazyLock<SkyTables> = LazyLock::new(|| {
    let text = include_str!("../data/sky/hosek_wilkie_rgb.txt");
    let x: Vec<f64> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .flat_map(str::split_whitespace)
        .map(|x| {
            x.parse()
                .expect("core/data/sky/hosek_wilkie_rgb.txt is numbers")
        })
        .collect();
    assert_eq!(x.len(), 3 * 1080 + 3 * 120, "hosek_wilkie_rgb.txt's size");
    let config = |c: usize| x[c * 1080..(c + 1) * 1080].to_vec();
    let radiance = |c: usize| x[3240 + c * 120..3240 + (c + 1) * 120].to_vec();
    SkyTables {
        config: [config(0), config(1), config(2)],
        radiance: [radiance(0), radiance(1), radiance(2)],
    }
});

/// The quintic Bézier blend of `stride`-spaced control points `m[k * stride]`, k = 0..6.
fn bezier5(m: &[f64], stride: usize, s: f64) -> f64 {
    const BINOMIAL: [f64; 6] = [1.0, 5.0, 10.0, 10.0, 5.0, 1.0];
    (0..6)
        .map(|k| BINOMIAL[k] * (1.0 - s).powi(5 - k as i32) * s.powi(k as i32) * m[k * stride])
        .sum()
}

/// The Hosek-Wilkie sky of one solar elevation, turbidity and ground albedo per channel.
#[derive(Clone, Debug)]
pub struct HosekWilkieSky {
    /// A..I per channel.
    config: [[f64; 9]; 3],
    /// L_M per channel.
    radiance: [f64; 3],
}

impl HosekWilkieSky {
    /// `turbidity` in [1, 10], `albedo` per channel in [0, 1], `solar_elevation` (radians
    /// above the horizon) in [0, π/2].
    pub fn new(turbidity: f64, albedo: DVec3, solar_elevation: f64) -> HosekWilkieSky {
        let tables = &*SKY_TABLES;
        let t_int = (turbidity as usize).clamp(1, 10);
        let t_rem = turbidity - t_int as f64;
        let s = (solar_elevation / FRAC_PI_2).powf(1.0 / 3.0);
        let mut config = [[0.0; 9]; 3];
        let mut radiance = [0.0; 3];
        for c in 0..3 {
            let a = albedo[c];
            // (albedo index, turbidity index, weight): the four corners of the bilinear
            // blend; turbidity 10 has no upper neighbour.
            let mut corners = vec![
                (0, t_int - 1, (1.0 - a) * (1.0 - t_rem)),
                (1, t_int - 1, a * (1.0 - t_rem)),
            ];
            if t_int < 10 {
                corners.push((0, t_int, (1.0 - a) * t_rem));
                corners.push((1, t_int, a * t_rem));
            }
            for (alb, tur, w) in corners {
                let m = &tables.config[c][9 * 6 * (10 * alb + tur)..];
                for (i, p) in config[c].iter_mut().enumerate() {
                    *p += w * bezier5(&m[i..], 9, s);
                }
                let r = &tables.radiance[c][6 * (10 * alb + tur)..];
                radiance[c] += w * bezier5(r, 1, s);
            }
        }
        HosekWilkieSky { config, radiance }
    }

    /// The radiance (linear sRGB, before Mitsuba's normalisation) at zenith angle `theta`
    /// and angle `gamma` from the sun.
    pub fn radiance(&self, theta: f64, gamma: f64) -> DVec3 {
        let (cos_theta, cos_gamma) = (theta.cos(), gamma.cos());
        let f = |c: &[f64; 9]| {
            let exp_m = (c[4] * gamma).exp();
            let ray_m = cos_gamma * cos_gamma;
            let mie_m = (1.0 + cos_gamma * cos_gamma)
                / (1.0 + c[8] * c[8] - 2.0 * c[8] * cos_gamma).powf(1.5);
            let zenith = cos_theta.sqrt();
            (1.0 + c[0] * (c[1] / (cos_theta + 0.01)).exp())
                * (c[2] + c[3] * exp_m + c[5] * ray_m + c[6] * mie_m + c[7] * zenith)
        };
        DVec3::new(
            f(&self.config[0]) * self.radiance[0],
            f(&self.config[1]) * self.radiance[1],
            f(&self.config[2]) * self.radiance[2],
        )
    }
}

/// Mitsuba 0.6's `sunsky` (or, without one part, its `sky` or `sun`) in the light's frame.
#[derive(Clone, Debug)]
pub struct SunSky {
    /// Where the sun is, before `stretch`.
    pub sun: Spherical,
    /// Atmospheric turbidity in [1, 10].
    pub turbidity: f64,
    /// The ground's albedo per channel in [0, 1] (the sky only).
    pub albedo: DVec3,
    /// Stretches the sky over the horizon, in [1, 2]: the sky at θ is the model's at
    /// θ / stretch, and the sun sits at θ_s · stretch.
    pub stretch: f64,
    /// Radiance scales; 0 leaves that part out.
    pub sky_scale: f64,
    pub sun_scale: f64,
    /// The sun's angular radius in units of the true sun's; > 0.
    pub sun_radius_scale: f64,
    /// Continue the sky below the horizon (Mitsuba's `extend`).
    pub extend: bool,
}

impl SunSky {
    /// Checks the ranges Mitsuba 0.6 checks: Err(parameter, message).
    pub fn validate(&self) -> Result<(), (&'static str, String)> {
        if !(1.0..=10.0).contains(&self.turbidity) {
            return Err((
                "turbidity",
                format!("must be in [1, 10], found {}", self.turbidity),
            ));
        }
        if !(1.0..=2.0).contains(&self.stretch) {
            return Err((
                "stretch",
                format!("must be in [1, 2], found {}", self.stretch),
            ));
        }
        if self.albedo.min_element() < 0.0 || self.albedo.max_element() > 1.0 {
            return Err((
                "albedo",
                format!("must be in [0, 1], found {}", self.albedo),
            ));
        }
        if self.sky_scale > 0.0 && self.sun.theta > FRAC_PI_2 {
            return Err((
                "sun_direction",
                format!(
                    "the sun is {:.2}° below the horizon, which the sky model does not cover",
                    (self.sun.theta - FRAC_PI_2).to_degrees()
                ),
            ));
        }
        if self.sun_scale > 0.0 && (self.sun_radius_scale <= 0.0 || self.sun_radius_scale.is_nan())
        {
            return Err((
                "sun_radius_scale",
                format!(
                    "must be > 0 for a sun in the map, found {}",
                    self.sun_radius_scale
                ),
            ));
        }
        Ok(())
    }

    /// The sun's direction in the light's frame (after `stretch`).
    pub fn sun_direction(&self) -> DVec3 {
        Spherical {
            theta: self.sun.theta * self.stretch,
            phi: self.sun.phi,
        }
        .direction()
    }

    /// The sun's radiance (before the radius scale dims it), sun_scale included.
    pub fn sun_radiance(&self) -> DVec3 {
        sun_radiance(self.sun.theta, self.turbidity) * self.sun_scale
    }

    /// The solid angle of the true sun's disc.
    pub fn sun_solid_angle() -> f64 {
        2.0 * PI * (1.0 - SUN_HALF_APERTURE_DEG.to_radians().cos())
    }

    /// The sky model of this sun and atmosphere.
    pub fn model(&self) -> HosekWilkieSky {
        HosekWilkieSky::new(self.turbidity, self.albedo, FRAC_PI_2 - self.sun.theta)
    }

    /// The sky's radiance (sky_scale included) towards `dir` in the light's frame; `model`
    /// is [`Self::model`].
    pub fn sky_radiance(&self, model: &HosekWilkieSky, dir: Spherical) -> DVec3 {
        let mut theta = dir.theta / self.stretch;
        if theta.cos() <= 0.0 {
            if !self.extend {
                return DVec3::ZERO;
            }
            theta = FRAC_PI_2 - 1e-4;
        }
        let (sun_theta, sun_phi) = (self.sun.theta, self.sun.phi);
        let cos_gamma = theta.cos() * sun_theta.cos()
            + theta.sin() * sun_theta.sin() * (dir.phi - sun_phi).cos();
        let gamma = cos_gamma.clamp(-1.0, 1.0).acos();
        let mut l = (model.radiance(theta, gamma) / SKY_RGB_NORMALISATION).max(DVec3::ZERO);
        if self.extend {
            let x = (2.0 - 2.0 * dir.theta / PI).clamp(0.0, 1.0);
            l *= x * x * (3.0 - 2.0 * x);
        }
        l * self.sky_scale
    }

    /// The sky and the sun in a `width` x `width / 2` latitude-longitude map in foton's
    /// layout ([`crate::envmap::EnvironmentMap::new`]: column i at φ = 2π (i + 1/2) / width,
    /// row j at θ = π j / (height - 1)).
    pub fn rasterize(&self, width: usize) -> Bitmap {
        let (w, h) = (width.max(4), (width / 2).max(3));
        let mut texels = vec![DVec3::ZERO; w * h];
        if self.sky_scale > 0.0 {
            let model = self.model();
            for j in 0..h {
                let theta = PI * j as f64 / (h - 1) as f64;
                for i in 0..w {
                    let phi = 2.0 * PI * (i as f64 + 0.5) / w as f64;
                    texels[j * w + i] = self.sky_radiance(&model, Spherical { theta, phi });
                }
            }
        }
        if self.sun_scale > 0.0 {
            self.splat_sun(&mut texels, w, h);
        }
        let texels = texels
            .into_iter()
            .map(|c| c.as_vec3())
            .collect::<Vec<Vec3>>();
        Bitmap::new(w, h, texels).expect("w x h texels")
    }

    fn splat_sun(&self, texels: &mut [DVec3], w: usize, h: usize) {
        let cos_cone = (SUN_HALF_APERTURE_DEG.to_radians() * self.sun_radius_scale).cos();
        // Mitsuba's generous count: a thousand samples per texel the disc covers.
        let covered = 0.5 * (1.0 - cos_cone);
        let n = ((w * w / 2) as f64 * covered * 1000.0).max(100.0) as usize;
        let texel_solid_angle = (2.0 * PI / w as f64) * (PI / (h - 1) as f64);
        let value = self.sun_radiance() * Self::sun_solid_angle() / (n as f64 * texel_solid_angle);
        let axis = self.sun_direction();
        let (s, t) = axis.any_orthonormal_pair();
        for k in 0..n {
            let (u1, u2) = sample02(k as u32);
            let cos_theta = (1.0 - u1) + u1 * cos_cone;
            let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
            let (sp, cp) = (2.0 * PI * u2).sin_cos();
            let d = s * (cp * sin_theta) + t * (sp * sin_theta) + axis * cos_theta;
            let sph = Spherical::of(d.normalize());
            let x = ((sph.phi * w as f64 / (2.0 * PI)) as usize).min(w - 1);
            let y = ((sph.theta * (h - 1) as f64 / PI).round() as usize).min(h - 1);
            let sin_row = (1.0 - d.y * d.y).max(0.0).sqrt();
            texels[y * w + x] += value / sin_row.max(1e-3);
        }
    }
}

/// The n-th point of the (0, 2) sequence: the base-2 radical inverse and Sobol's second
/// dimension (unscrambled).
fn sample02(n: u32) -> (f64, f64) {
    let radical = n.reverse_bits() as f64 / 4294967296.0;
    let (mut bits, mut v, mut m) = (0u32, 1u32 << 31, n);
    while m != 0 {
        if m & 1 != 0 {
            bits ^= v;
        }
        m >>= 1;
        v ^= v >> 1;
    }
    (radical, bits as f64 / 4294967296.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spherical_coordinates_round_trip() {
        for (theta, phi) in [(0.3, 0.2), (1.2, 3.0), (2.5, 5.9)] {
            let s = Spherical::of(Spherical { theta, phi }.direction());
            assert!((s.theta - theta).abs() < 1e-12 && (s.phi - phi).abs() < 1e-12);
        }
    }

    /// Mitsuba 0.6's default sun (Tokyo, 10 July 2010, 15:00 JST = 06:00 UTC), checked by
    /// hand: declination +22.3°, equation of time -5 min, so apparent solar time 15:14 at
    /// 139.69° E and the hour angle 48.4°; then sin(elevation) = sin φ sin δ + cos φ cos δ
    /// cos H gives 46.1°, and the azimuth from north 360° - 94.1° (afternoon: west).
    #[test]
    fn the_default_sun_stands_where_the_almanac_puts_it() {
        let s = sun_position(&DateTime::default(), &Place::default());
        let elevation = 90.0 - s.theta.to_degrees();
        let azimuth = s.phi.to_degrees();
        assert!((elevation - 46.1).abs() < 0.3, "elevation {elevation}");
        assert!((azimuth - 265.9).abs() < 0.5, "azimuth {azimuth}");
    }

    /// The sun's disc keeps the true sun's power whatever its radius scale and the map's
    /// resolution: the map's integral equals L_sun Ω_sun.
    #[test]
    fn the_rasterised_sun_carries_the_suns_power() {
        for (radius_scale, width) in [(1.0, 512), (10.0, 256), (20.0, 512)] {
            let sky = SunSky {
                sun: Spherical {
                    theta: 0.9,
                    phi: 1.0,
                },
                turbidity: 3.0,
                albedo: DVec3::splat(0.2),
                stretch: 1.0,
                sky_scale: 0.0,
                sun_scale: 1.0,
                sun_radius_scale: radius_scale,
                extend: false,
            };
            let map = crate::envmap::EnvironmentMap::new(
                &sky.rasterize(width),
                1.0,
                glam::Mat3::IDENTITY,
            )
            .unwrap();
            let want = sky.sun_radiance() * SunSky::sun_solid_angle();
            let got = map.integral().as_dvec3();
            let err = ((got - want) / want).abs().max_element();
            assert!(
                err < 0.01,
                "scale {radius_scale}, {width}: {got} against {want}"
            );
        }
    }

    /// The Hosek-Wilkie sky is brightest around the sun, and its zenith brightens as the
    /// sun climbs.
    #[test]
    fn the_sky_is_brightest_near_the_sun() {
        let sky = HosekWilkieSky::new(3.0, DVec3::splat(0.2), 0.6);
        let near = sky.radiance(FRAC_PI_2 - 0.6, 0.05);
        let far = sky.radiance(FRAC_PI_2 - 0.6, 2.0);
        assert!(near.min_element() > 2.0 * far.max_element(), "{near} {far}");
        let low = HosekWilkieSky::new(3.0, DVec3::splat(0.2), 0.2).radiance(0.0, FRAC_PI_2 - 0.2);
        let high = HosekWilkieSky::new(3.0, DVec3::splat(0.2), 1.2).radiance(0.0, FRAC_PI_2 - 1.2);
        assert!(high.y > low.y, "{high} {low}");
    }

    #[test]
    fn sample02_is_a_0_2_sequence() {
        // Every elementary interval of area 1/16 holds exactly one of the first 16 points.
        for (a, b) in [(1u32, 16u32), (2, 8), (4, 4), (8, 2), (16, 1)] {
            let mut seen = [false; 16];
            for n in 0..16 {
                let (x, y) = sample02(n);
                let cell = (x * a as f64) as usize * b as usize + (y * b as f64) as usize;
                assert!(!seen[cell], "({a}, {b}): cell {cell} twice");
                seen[cell] = true;
            }
        }
    }
}
