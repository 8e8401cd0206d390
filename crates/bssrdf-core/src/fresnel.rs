//! Fresnel reflectance of a smooth dielectric boundary (pbrt-v4 §9.3).

/// Unpolarised Fresnel reflectance for light arriving at the boundary with cosine `cos_i`
/// (measured from the normal on the incident side, `cos_i ∈ [0, 1]`) and relative index
/// `eta = n_transmitted / n_incident`. Returns 1 under total internal reflection.
pub fn dielectric(cos_i: f64, eta: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}
