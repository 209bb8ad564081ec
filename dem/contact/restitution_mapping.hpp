#pragma once
// Exact restitution for the damped Hertz contact.
//
// With F = K d^{3/2} + C d^{1/4} d', K = (4/3) Y* sqrt(R*), C = 2 sqrt(5/6) b sqrt(2 Y* sqrt(R*) m*),
// scaling d by d* = (m* v0^2 / K)^{2/5} and t by sqrt(m*/(K sqrt(d*))) gives
//     x'' = -x^{3/2} - c x^{1/4} x',   x(0) = 0, x'(0) = 1,   c = sqrt(5) b,
// so the restitution depends on b alone, not on the impact speed (Antypov & Elliott 2011,
// EPL 94:50004). The popular choice b = -ln e / sqrt(ln^2 e + pi^2) (Tsuji et al. 1992)
// carries over the linear-oscillator result and misses the requested e by up to ~10 %;
// we instead solve the scaled equation numerically and invert it, so the measured
// restitution equals the requested one.
namespace grainflow {

// Restitution of the scaled Hertz oscillator with damping parameter b >= 0.
double hertz_restitution(double b);

// The b >= 0 with hertz_restitution(b) == e, for e in (0, 1]; b = 0 for e = 1.
double hertz_damping_for_restitution(double e);

// Dimensionless contact duration of the elastic scaled oscillator (tests use it).
double hertz_scaled_contact_time(double b);

}  // namespace grainflow
