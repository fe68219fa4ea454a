#pragma once
// The geometric kernel between two clusters of surface, averaged over their extent, for the
// far links of hierarchical radiosity (linker.cpp, tree_walk.cpp), which read it at the clusters'
// centres.

#include "raytrace_core/util/math.h"

namespace gilt::radiosity::solver {

using raytrace_core::Vec3;

/// Covariance of the points of triangle (a, b, c), uniform by area, about its centroid g:
/// Σ_v (v − g)(v − g)ᵀ / 12.
glm::dmat3 triangle_covariance(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

/// How the kernel G(u) = (n_r·u)(−n_s·u) / |u|⁴ (cos θ_r cos θ_s / r² for u the segment from a
/// receiving point to a sending one) averages over two clusters, against its value at their
/// centres, d = c_S − c_R. A far link that reads G(d) overstates ends that face each other: for
/// coaxial disks of radii a and b at distance h the form factor is about b² / (h² + a² + b²),
/// not b² / h².
///
/// To second order in the ends' extent, E[G(d + y − x)] = G(d) (1 + δ), δ = ½ tr(H C) / G(d), for
/// H the Hessian of G at d and C the covariance of y − x (the sum of the two ends' covariances,
/// the ends independent). With p = n_r·d, q = −n_s·d and s = d·d:
///   δ = −n_rᵀC n_s / (p q) + 4 n_sᵀC d / (q s) − 4 n_rᵀC d / (p s) − 2 tr C / s + 12 dᵀC d / s².
///
/// Returns the factor on G(d): 1 / (1 − δ) where δ < 0, which is exact to first order in C and
/// exact in full for coaxial disks (there δ = −(a² + b²) / h²), and stays positive for ends as
/// large as their distance; 1 + δ, at most 2, otherwise. 1 where an end does not face the other
/// at the centres (p ≤ 0 or q ≤ 0), where the expansion says nothing. It is only a guide where
/// the segments between the ends graze either of them: there the kernel's cut at cos θ = 0 is
/// not smooth.
///
/// `n_r` and `n_s` are the ends' unit normals, n_s facing away from the receiver. An end whose
/// elements face both ways is given ±d / |d|: the gathering gives each of its elements its own
/// cosine along d, so only the distance and the direction vary.
float cluster_kernel_scale(const Vec3& d, const Vec3& n_r, const Vec3& n_s, const glm::mat3& C);

}  // namespace gilt::radiosity::solver
