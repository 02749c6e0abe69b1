#pragma once
// A recording's outcomes as two modes, for the leg search (leg_search.h): a weak leg makes the
// robot sag now and then, far from how it otherwise walks, and how often and in which direction
// it sags tells which leg is weak. One Gaussian per command must stretch to cover the sags (and
// then fits neither); here
//   p(x | c, z) = (1 - p - e) N(x; core(c, z)) + p N(x - ref(c, z); sag) + e N(x - ref(c, z); 0, k^2 S)
// with core the recording's own model (the reference family) fitted on the samples that the
// reference calls ordinary, sag one Gaussian of the deviations of those it calls sags (squared
// Mahalanobis distance under the reference beyond d + 4 sqrt(2d), about the chi^2 99.9% point),
// p their share, and a broad component (share e, k times the reference's pooled spread S) so that
// a fall no recording made costs tens of nats, not thousands. The reference is fitted on the sim
// set, which has seen none of the recordings nor the real samples, so every recording's sags and
// the real robot's are measured against the same thing.
#include <Eigen/Dense>
#include <vector>

#include "core/gaussian.h"
#include "sim2real/linear_gaussian.h"
#include "sim2real/samples.h"

namespace dgmm::sim2real {

struct SagReference {
  LinearGaussianModel model;
  Eigen::MatrixXd spread;  // pooled covariance of its residuals on the samples it was fitted on
  double cut = 0;          // squared Mahalanobis distance beyond which a sample is a sag
};

SagReference MakeSagReference(const Samples& sim, const LinearGaussianOptions& options);

struct SagOptions {
  double broad_share = 0.01;  // e
  double broad_scale = 10.0;  // k
  // The sag covariance gets floor * diag(S) added (a handful of sags in six dimensions).
  double floor = 0.05;
};

struct SagModel {
  LinearGaussianModel core;
  Gaussian sag;       // of x - ref(c, z); a broad one (k^2 S) when too few sags to fit one
  double share = 0;   // p: (sags + 1) / (samples + 2)
  int sags = 0;
};

// Fitted on `rows` of s (all when empty).
SagModel FitSagModel(const Samples& s, const std::vector<int>& rows, const SagReference& ref,
                     const LinearGaussianOptions& model, const SagOptions& options);

// log p(x_i | c_i, z_i) per sample of s.
Eigen::VectorXd SagLogLikelihood(const SagModel& m, const SagReference& ref, const Samples& s,
                                 const SagOptions& options);

// The broad component alone, log N(x_i - ref(c_i, z_i); 0, k^2 S) per sample of s: the floor that
// SagLogLikelihood gives every sample, for scoring another model with the same floor.
Eigen::VectorXd BroadLogDensity(const SagReference& ref, const Samples& s, const SagOptions& options);

}  // namespace dgmm::sim2real
