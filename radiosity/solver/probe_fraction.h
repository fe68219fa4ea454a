#pragma once
// Visible fractions after a probe. A few shadow rays probe a source; where they all pass or all
// fail the probe's answer stands, and only where they disagree (a penumbra) more rays are traced.
// The rays that decide cannot also be counted plainly: a probe that passes whole is likelier
// where more of the source is open, but it stops whatever the true fraction, so hits / rays over
// the extended rays is biased (for a source 80 % visible, a 4-ray probe extended to 16 reads
// 0.86 on average). The estimators here are unbiased over the whole rule: each is the expected
// value of the first probe ray given what was seen (Rao–Blackwell), which for one exchangeable
// sequence is the stopped-Bernoulli estimator of Girshick, Mosteller & Savage (1946).

#include <array>

namespace gilt::radiosity::solver {

/// `hits` of `rays` rays, one exchangeable sequence, the first `probe` of which found the source
/// partly hidden. Of the sequences with `hits` hits in `rays` whose first `probe` are mixed, the
/// share that begin with a hit: k / R − a over 1 − a − b, with a = C(R − p, k − p) / C(R, k) and
/// b = C(R − p, k) / C(R, k). Between 1 / p and (p − 1) / p. Needs 0 < hits < rays, probe < rays.
double extended_fraction(int hits, int rays, int probe);

/// A stratified probe of one ray per quarter of the source's sample square that found a mix,
/// then `rays_per_quarter` − 1 more independent rays in each quarter: `hits[j]` counts quarter j's
/// (its probe ray included). With q_j = hits[j] / rays_per_quarter, the chance that quarter j's
/// probe ray passed given its count, and the probe mixed: the mean over the quarters of
/// (q_j − Π q) / (1 − Π q − Π (1 − q)). Needs rays_per_quarter ≥ 2 and counts a mixed probe allows.
double quartered_fraction(const std::array<int, 4>& hits, int rays_per_quarter);

}  // namespace gilt::radiosity::solver
