/// @file
/// Where a body writes a matrix block (mass matrix, force Jacobians): a dense matrix, or
/// the DAE Jacobian at an offset, with a scale factor. Bodies write only their structural
/// non-zeros, so a large flexible body fills a sparse Jacobian in O(non-zeros).
#pragma once

#include "core/sparse_pattern.hpp"
#include "core/types.hpp"

namespace flexmbd {

class MatrixSink {
 public:
  /// Into a dense matrix: M(i, j) += scale * value (implicit, so MatX arguments work).
  MatrixSink(MatX& M, double scale = 1.0) : dense_(&M), scale_(scale) {}
  /// Into a dense matrix at an offset: M(row0 + i, col0 + j) += scale * value.
  MatrixSink(MatX& M, int row0, int col0, double scale = 1.0) : dense_(&M), row0_(row0), col0_(col0), scale_(scale) {}
  /// Into the DAE Jacobian: J(row0 + i, col0 + j) += scale * value.
  MatrixSink(JacobianSink& J, int row0, int col0, double scale = 1.0)
      : jacobian_(&J), row0_(row0), col0_(col0), scale_(scale) {}

  void add(int i, int j, double value) const {
    if (dense_) {
      (*dense_)(row0_ + i, col0_ + j) += scale_ * value;
    } else {
      jacobian_->add(row0_ + i, col0_ + j, scale_ * value);
    }
  }
  /// Block B at (i0, j0), every entry (dense blocks: frame rows and columns). B is
  /// evaluated into a matrix of its compile-time size: of fixed size it allocates nothing.
  template <class Derived>
  void addBlock(int i0, int j0, const Eigen::MatrixBase<Derived>& B) const {
    const Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime> b = B;  // column-major
    for (Eigen::Index j = 0; j < b.cols(); ++j) {
      const int rows = static_cast<int>(b.rows());
      if (dense_) {
        dense_->block(row0_ + i0, col0_ + j0 + j, rows, 1) += scale_ * b.col(j);
      } else {
        jacobian_->addColumn(col0_ + j0 + static_cast<int>(j), row0_ + i0, nullptr, b.col(j).data(), rows, scale_);
      }
    }
  }
  /// Column j, rows i0 .. i0 + n - 1: += value(k) (a column computed on the fly, e.g. the
  /// transpose of a row block, without forming it).
  template <class Fn>
  void addColumn(int i0, int j, int n, Fn&& value) const {
    if (dense_) {
      for (int k = 0; k < n; ++k) (*dense_)(row0_ + i0 + k, col0_ + j) += scale_ * value(k);
    } else {
      jacobian_->addColumnSegment(col0_ + j, row0_ + i0, n, value, scale_);
    }
  }
  /// s * S at (i0, j0), its stored entries only.
  void addSparse(int i0, int j0, const SpMat& S, double s = 1.0) const {
    if (dense_ || !S.isCompressed()) {
      for (int j = 0; j < S.outerSize(); ++j) {
        for (SpMat::InnerIterator it(S, j); it; ++it) add(i0 + static_cast<int>(it.row()), j0 + j, s * it.value());
      }
      return;
    }
    const int* outer = S.outerIndexPtr();
    for (int j = 0; j < S.outerSize(); ++j) {
      jacobian_->addColumn(col0_ + j0 + j, row0_ + i0, S.innerIndexPtr() + outer[j], S.valuePtr() + outer[j],
                           outer[j + 1] - outer[j], scale_ * s);
    }
  }

 private:
  MatX* dense_ = nullptr;
  JacobianSink* jacobian_ = nullptr;
  int row0_ = 0, col0_ = 0;
  double scale_ = 1.0;
};

}  // namespace flexmbd
