#pragma once
// Small fit problems for tests of the selection and the ties: sim-side fields filled so that the
// whitened designs are the designs, real residuals r0 = shift(i, j) + N(0, 1).
#include <cmath>
#include <random>
#include <vector>

#include "sim2real/selection.h"

namespace dgmm::sim2real::test {

// Fills the sim-side fields of `fp` (whitened designs = designs, unit log-normaliser) with real
// residuals r0 = shift(i, j) + N(0, 1), episodes of 5 samples and 3 commands; returns the rows
// 0..n-1 and their 5 episode folds in *fold.
template <typename Shift>
inline std::vector<int> FillResidualsAndFolds(FitProblem* fp, Shift shift, std::uint64_t seed, std::vector<int>* fold) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0, 1);
  fp->g = fp->d;
  fp->r0.resize(fp->n, fp->dx);
  fp->log_norm = Eigen::VectorXd::Constant(fp->n, -fp->dx * 0.5 * std::log(2 * M_PI));
  for (int i = 0; i < fp->n; ++i) {
    for (int j = 0; j < fp->dx; ++j) fp->r0(i, j) = shift(i, j) + unit(rng);
    fp->episode.push_back(i / 5);
    fp->command.push_back(i % 3);
  }
  std::vector<int> rows(fp->n);
  for (int i = 0; i < fp->n; ++i) rows[i] = i;
  std::mt19937_64 frng(1);
  *fold = MakeFolds(*fp, rows, 5, frng);
  return rows;
}

// An empty problem of n samples of dimension dx.
inline FitProblem ToyProblem(int n, int dx) {
  FitProblem fp;
  fp.n = n;
  fp.dx = dx;
  return fp;
}

}  // namespace dgmm::sim2real::test
