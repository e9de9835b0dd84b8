#include <knee_contact/solver/sparse_cholesky.h>

#include <metis.h>

#include <algorithm>
#include <new>
#include <stdexcept>
#include <string>

namespace knee_contact
{
  namespace sparse_cholesky
  {
    CsrMatrix
    condense(const SparseMatrix<double>      &matrix,
             const AffineConstraints<double> &constraints)
    {
      SparseMatrix<double> copy(matrix.get_sparsity_pattern());
      copy.copy_from(matrix);
      constraints.condense(copy);
      CsrMatrix  result;
      const auto n = matrix.m();
      result.row_start.reserve(n + 1);
      result.row_start.push_back(0);
      for (types::global_dof_index i = 0; i < n; ++i)
        {
          for (auto it = copy.begin(i); it != copy.end(i); ++it)
            if (it->value() != 0 || it->column() == i)
              {
                result.column.push_back(it->column());
                result.value.push_back(it->value());
              }
          result.row_start.push_back(result.column.size());
        }
      return result;
    }



    CsrMatrix
    pattern_of(const SparsityPattern &pattern)
    {
      CsrMatrix result;
      result.row_start.reserve(pattern.n_rows() + 1);
      result.row_start.push_back(0);
      result.column.reserve(pattern.n_nonzero_elements());
      for (types::global_dof_index i = 0; i < pattern.n_rows(); ++i)
        {
          for (auto it = pattern.begin(i); it != pattern.end(i); ++it)
            result.column.push_back(it->column());
          result.row_start.push_back(result.column.size());
        }
      return result;
    }



    Vector<double>
    condense(const StiffnessResidual         &residual,
             const Vector<double>            &rhs,
             const AffineConstraints<double> &constraints)
    {
      Vector<double> g(rhs.size());
      for (const auto &line : constraints.get_lines())
        g(line.index) = line.inhomogeneity;
      Vector<double> b(rhs.size());
      residual(b, g, rhs);
      for (const auto &line : constraints.get_lines())
        for (const auto &[j, c] : line.entries)
          b(j) += c * b(line.index);
      for (const auto &line : constraints.get_lines())
        b(line.index) = 0;
      return b;
    }



    void
    condense_homogeneous(const AffineConstraints<double> &constraints,
                         Vector<double>                  &v)
    {
      for (const auto &line : constraints.get_lines())
        for (const auto &[j, c] : line.entries)
          v(j) += c * v(line.index);
      for (const auto &line : constraints.get_lines())
        v(line.index) = 0;
    }



    void
    distribute_homogeneous(const AffineConstraints<double> &constraints,
                           Vector<double>                  &v)
    {
      for (const auto &line : constraints.get_lines())
        {
          double value = 0;
          for (const auto &[j, c] : line.entries)
            value += c * v(j);
          v(line.index) = value;
        }
    }



    std::vector<int>
    fill_reducing_ordering(const CsrMatrix                            &a,
                           const std::vector<types::global_dof_index> &last)
    {
      const std::size_t n = a.size();
      std::vector<bool> is_last(n, false);
      for (const auto d : last)
        is_last[d] = true;
      // Dofs with identical rows (sorted: deal.II stores the diagonal
      // first) belong to one vertex.
      std::vector<int>                     node_of(n, -1);
      std::vector<std::vector<int>>        dofs_of_node;
      std::vector<types::global_dof_index> row_i, row_j;
      const auto sorted = [&](const std::size_t i, auto &row) {
        row.assign(a.column.begin() + a.row_start[i],
                   a.column.begin() + a.row_start[i + 1]);
        std::sort(row.begin(), row.end());
      };
      for (std::size_t i = 0; i < n; ++i)
        if (!is_last[i])
          {
            if (i > 0 && !is_last[i - 1] && node_of[i - 1] >= 0 &&
                dofs_of_node[node_of[i - 1]].size() < 3)
              {
                sorted(i - 1, row_j);
                sorted(i, row_i);
                if (row_i == row_j)
                  {
                    node_of[i] = node_of[i - 1];
                    dofs_of_node[node_of[i]].push_back(i);
                    continue;
                  }
              }
            node_of[i] = dofs_of_node.size();
            dofs_of_node.push_back({static_cast<int>(i)});
          }

      const idx_t        n_nodes = dofs_of_node.size();
      std::vector<idx_t> xadj(n_nodes + 1, 0), adjncy;
      std::vector<idx_t> neighbours;
      for (idx_t v = 0; v < n_nodes; ++v)
        {
          neighbours.clear();
          for (const int i : dofs_of_node[v])
            for (std::size_t k = a.row_start[i]; k < a.row_start[i + 1]; ++k)
              {
                const auto j = a.column[k];
                if (!is_last[j] && node_of[j] != v)
                  neighbours.push_back(node_of[j]);
              }
          std::sort(neighbours.begin(), neighbours.end());
          neighbours.erase(std::unique(neighbours.begin(), neighbours.end()),
                           neighbours.end());
          adjncy.insert(adjncy.end(), neighbours.begin(), neighbours.end());
          xadj[v + 1] = adjncy.size();
        }
      std::vector<idx_t> perm(n_nodes), iperm(n_nodes);
      if (n_nodes > 0)
        {
          idx_t options[METIS_NOPTIONS];
          METIS_SetDefaultOptions(options);
          options[METIS_OPTION_NUMBERING] = 0;
          idx_t      nv                   = n_nodes;
          const auto status =
            METIS_NodeND(&nv,
                         xadj.data(),
                         adjncy.empty() ? nullptr : adjncy.data(),
                         nullptr,
                         options,
                         perm.data(),
                         iperm.data());
          if (status == METIS_ERROR_MEMORY)
            throw std::bad_alloc();
          if (status != METIS_OK)
            throw std::runtime_error("METIS failed to order the stiffness "
                                     "matrix");
        }
      std::vector<int> order;
      order.reserve(n);
      for (const idx_t v : perm)
        for (const int i : dofs_of_node[v])
          order.push_back(i);
      for (const auto d : last)
        order.push_back(d);
      return order;
    }



    SparseCholesky::SparseCholesky()
    {
      cholmod_start(&common);
      common.print                      = 0;
      common.error_handler              = nullptr;
      common.supernodal                 = CHOLMOD_SUPERNODAL;
      common.nmethods                   = 1;
      common.method[0].ordering         = CHOLMOD_GIVEN;
      common.postorder                  = false;
      common.quick_return_if_not_posdef = true;
    }



    SparseCholesky::~SparseCholesky()
    {
      if (factor != nullptr)
        cholmod_free_factor(&factor, &common);
      if (matrix != nullptr)
        cholmod_free_sparse(&matrix, &common);
      cholmod_finish(&common);
    }



    void
    SparseCholesky::analyse(const CsrMatrix        &a,
                            const std::vector<int> &perm,
                            const bool              postorder)
    {
      common.postorder = postorder;
      if (factor != nullptr)
        cholmod_free_factor(&factor, &common);
      if (matrix != nullptr)
        cholmod_free_sparse(&matrix, &common);
      order               = perm;
      const std::size_t n = a.size();
      // The upper triangle by columns is the lower one of C by rows.
      std::size_t nnz = 0;
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t k = a.row_start[i]; k < a.row_start[i + 1]; ++k)
          nnz += a.column[k] <= i;
      matrix = cholmod_allocate_sparse(
        n, n, nnz, false, true, 1, CHOLMOD_REAL, &common);
      check("allocate");
      auto *p = static_cast<int *>(matrix->p);
      auto *r = static_cast<int *>(matrix->i);
      nnz     = 0;
      for (std::size_t i = 0; i < n; ++i)
        {
          p[i] = nnz;
          for (std::size_t k = a.row_start[i]; k < a.row_start[i + 1]; ++k)
            if (a.column[k] <= i)
              r[nnz++] = a.column[k];
        }
      p[n]   = nnz;
      factor = cholmod_analyze_p(matrix, order.data(), nullptr, 0, &common);
      check("analyse");
      lnz = common.lnz;
      fl  = common.fl;
    }



    bool
    SparseCholesky::factorise(const CsrMatrix  &a,
                              const std::size_t n_shifted,
                              const double      shift)
    {
      Assert(matrix != nullptr && factor != nullptr,
             ExcMessage("factorise() before analyse()"));
      const std::size_t n = a.size();
      std::vector<bool> shifted(n, false);
      for (std::size_t k = order.size() - n_shifted; k < order.size(); ++k)
        shifted[order[k]] = true;
      auto       *x   = static_cast<double *>(matrix->x);
      std::size_t nnz = 0;
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t k = a.row_start[i]; k < a.row_start[i + 1]; ++k)
          if (a.column[k] <= i)
            x[nnz++] =
              a.value[k] + (a.column[k] == i && shifted[i] ? shift : 0.);
      Assert(nnz == std::size_t(static_cast<const int *>(matrix->p)[n]),
             ExcMessage("factorise() with a pattern other than analysed"));
      (void)nnz;
      return factorise_values();
    }



    bool
    SparseCholesky::factorise(const SparseMatrix<double> &a)
    {
      Assert(matrix != nullptr && factor != nullptr,
             ExcMessage("factorise() before analyse()"));
      auto       *x   = static_cast<double *>(matrix->x);
      std::size_t nnz = 0;
      for (types::global_dof_index i = 0; i < a.m(); ++i)
        for (auto it = a.begin(i); it != a.end(i); ++it)
          if (it->column() <= i)
            x[nnz++] = it->value();
      Assert(nnz == std::size_t(static_cast<const int *>(matrix->p)[a.m()]),
             ExcMessage("factorise() with a pattern other than analysed"));
      return factorise_values();
    }



    bool
    SparseCholesky::factorise_values()
    {
      cholmod_factorize(matrix, factor, &common);
      if (common.status == CHOLMOD_NOT_POSDEF)
        return false;
      check("factorise");
      return true;
    }



    void
    SparseCholesky::release_matrix()
    {
      if (matrix != nullptr)
        cholmod_free_sparse(&matrix, &common);
    }



    std::vector<int>
    SparseCholesky::final_last(const std::size_t k) const
    {
      const auto *perm = static_cast<const int *>(factor->Perm);
      return std::vector<int>(perm + factor->n - k, perm + factor->n);
    }



    double
    SparseCholesky::nnz_factor() const
    {
      return lnz;
    }



    double
    SparseCholesky::flops() const
    {
      return fl;
    }



    std::vector<double>
    SparseCholesky::trailing_block(const std::size_t k) const
    {
      const std::size_t   n = factor->n;
      std::vector<double> block(k * k, 0.);
      const auto         *super = static_cast<const int *>(factor->super);
      const auto         *pi    = static_cast<const int *>(factor->pi);
      const auto         *px    = static_cast<const int *>(factor->px);
      const auto         *s     = static_cast<const int *>(factor->s);
      const auto         *x     = static_cast<const double *>(factor->x);
      for (std::size_t sn = 0; sn < factor->nsuper; ++sn)
        {
          const std::size_t first = super[sn], end = super[sn + 1];
          if (end <= n - k)
            continue;
          const std::size_t n_rows = pi[sn + 1] - pi[sn];
          for (std::size_t col = std::max(first, n - k); col < end; ++col)
            for (std::size_t r = 0; r < n_rows; ++r)
              {
                const std::size_t row = s[pi[sn] + r];
                if (row >= col)
                  block[(col - (n - k)) * k + (row - (n - k))] =
                    x[px[sn] + r + (col - first) * n_rows];
              }
        }
      return block;
    }



    double
    SparseCholesky::memory_MB() const
    {
      if (factor == nullptr)
        return 0;
      return (factor->xsize * sizeof(double) + factor->ssize * sizeof(int)) /
             1048576.;
    }



    void
    SparseCholesky::solve(const int system, std::vector<double> &b)
    {
      cholmod_dense rhs;
      rhs.nrow         = b.size();
      rhs.ncol         = 1;
      rhs.nzmax        = b.size();
      rhs.d            = b.size();
      rhs.x            = b.data();
      rhs.z            = nullptr;
      rhs.xtype        = CHOLMOD_REAL;
      rhs.dtype        = CHOLMOD_DOUBLE;
      cholmod_dense *x = cholmod_solve(system, factor, &rhs, &common);
      check("solve");
      std::copy_n(static_cast<const double *>(x->x), b.size(), b.begin());
      cholmod_free_dense(&x, &common);
    }



    void
    SparseCholesky::check(const char *what)
    {
      if (common.status == CHOLMOD_OUT_OF_MEMORY)
        throw std::bad_alloc();
      if (common.status == CHOLMOD_TOO_LARGE)
        throw FactorTooLarge();
      if (common.status < CHOLMOD_OK)
        throw std::runtime_error(std::string("CHOLMOD failed to ") + what +
                                 " (status " + std::to_string(common.status) +
                                 ")");
    }
  } // namespace sparse_cholesky
} // namespace knee_contact
