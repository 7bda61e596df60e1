// Row-major Eigen matrices: the in-memory layout of 2-D datasets in files (HDF5, VTK), so that
// a (rows, cols) array in h5py/numpy is the same (rows, cols) matrix here.
#pragma once

#include <Eigen/Core>

namespace knit::io {
using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixXi = Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
}  // namespace knit::io
