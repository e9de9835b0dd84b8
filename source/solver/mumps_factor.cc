#include <knee_contact/base/memory.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/solver/sparse_factor.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>

#include <petscmat.h>

#include <algorithm>
#include <sstream>

namespace knee_contact
{
  std::string
  direct_factor_name(const DirectFactor factor)
  {
    switch (factor)
      {
        case DirectFactor::cholmod:
          return "CHOLMOD";
        case DirectFactor::mumps:
          return "MUMPS";
        default:
          return "automatic";
      }
  }



  DirectFactor
  resolve_direct_factor(const DirectFactor requested)
  {
    if (requested != DirectFactor::automatic)
      return requested;
    return parallel::n_ranks() > 1 ? DirectFactor::mumps
                                   : DirectFactor::cholmod;
  }



  namespace
  {
    /** A PETSc call that failed: one line naming it (PETSc prints nothing:
     * parallel::ensure_petsc() installs its return-only error handler). */
    void
    check(const PetscErrorCode code, const char *what)
    {
      AssertThrow(code == 0,
                  ExcMessage(std::string("MUMPS (through PETSc): ") + what +
                             " failed (PETSc error " + std::to_string(code) +
                             ")"));
    }



    /**
     * Why by hand: deal.II 9.4's PETScWrappers::SparseDirectMUMPS factorises
     * at every solve() and offers neither the symbolic analysis apart nor
     * MUMPS's own figures (INFO, INFOG); the sparse path factorises once
     * per active set and solves many times with one factor, so the PETSc
     * calls (Mat, MatGetFactor, MatSolve) are made here.
     */
    class MumpsFactor : public SparseFactor
    {
    public:
      explicit MumpsFactor(const SparsityPattern &pattern);
      ~MumpsFactor() override;

      bool
      factorise(const SparseMatrix<double> &a) override;

      void
      solve(std::vector<double> &b) override;

      double
      memory_MB() const override
      {
        return used_MB;
      }

      std::map<std::string, double>
      statistics() const override
      {
        return {{"mumps_ranks", parallel::n_ranks()},
                {"mumps_estimated_MB", estimated_MB},
                {"mumps_factor_entries", factor_entries},
                {"mumps_flops", flops}};
      }

    private:
      /** Copy this rank's rows of @p values into the PETSc matrix. */
      void
      set_rows(const SparseMatrix<double> &values);

      /** MUMPS's analysis of the matrix's pattern; refuses a factor that
       * would not fit. */
      void
      analyse();

      Mat        matrix = nullptr, factor = nullptr;
      Vec        rhs = nullptr, x = nullptr, whole = nullptr;
      VecScatter gather = nullptr;
      PetscInt   first = 0, last = 0;
      bool       analysed     = false;
      double     estimated_MB = 0, used_MB = 0, factor_entries = 0, flops = 0;
      std::vector<PetscInt> columns;
      std::vector<double>   row_values;
    };



    MumpsFactor::MumpsFactor(const SparsityPattern &pattern)
    {
      parallel::ensure_petsc();
      const MPI_Comm     comm = parallel::communicator();
      const unsigned int N = parallel::n_ranks(), r = parallel::rank();
      const auto         n = static_cast<PetscInt>(pattern.n_rows());
      AssertThrow(static_cast<types::global_dof_index>(n) == pattern.n_rows(),
                  ExcMessage("MUMPS (through PETSc): more rows than PETSc's "
                             "32-bit indices hold"));
      first = static_cast<PetscInt>(std::size_t(n) * r / N);
      last  = static_cast<PetscInt>(std::size_t(n) * (r + 1) / N);
      // Preallocation from the pattern: the entries of each own row in
      // the own block of columns and outside it.
      std::vector<PetscInt> in_block(last - first), off_block(last - first);
      for (PetscInt i = first; i < last; ++i)
        for (auto entry = pattern.begin(i); entry != pattern.end(i); ++entry)
          {
            const auto j = static_cast<PetscInt>(entry->column());
            ++(j >= first && j < last ? in_block : off_block)[i - first];
          }
      check(MatCreateAIJ(comm,
                         last - first,
                         last - first,
                         n,
                         n,
                         0,
                         in_block.data(),
                         0,
                         off_block.data(),
                         &matrix),
            "creating the matrix");
      check(MatSetOption(matrix, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption");
      check(MatSetOption(matrix, MAT_NO_OFF_PROC_ENTRIES, PETSC_TRUE),
            "MatSetOption");
      check(MatCreateVecs(matrix, &x, &rhs), "creating vectors");
      check(VecScatterCreateToAll(x, &gather, &whole), "VecScatterCreateToAll");
    }



    MumpsFactor::~MumpsFactor()
    {
      // Destroyed before PETSc is finalised (at exit); errors cannot be
      // reported from a destructor.
      VecScatterDestroy(&gather);
      VecDestroy(&whole);
      VecDestroy(&x);
      VecDestroy(&rhs);
      MatDestroy(&factor);
      MatDestroy(&matrix);
    }



    void
    MumpsFactor::set_rows(const SparseMatrix<double> &values)
    {
      for (PetscInt i = first; i < last; ++i)
        {
          columns.clear();
          row_values.clear();
          for (auto entry = values.begin(i); entry != values.end(i); ++entry)
            {
              columns.push_back(static_cast<PetscInt>(entry->column()));
              row_values.push_back(entry->value());
            }
          check(MatSetValues(matrix,
                             1,
                             &i,
                             columns.size(),
                             columns.data(),
                             row_values.data(),
                             INSERT_VALUES),
                "MatSetValues");
        }
      check(MatAssemblyBegin(matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
      check(MatAssemblyEnd(matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
    }



    void
    MumpsFactor::analyse()
    {
      check(MatGetFactor(matrix, MATSOLVERMUMPS, MAT_FACTOR_CHOLESKY, &factor),
            "MatGetFactor");
      // LDL^T of a symmetric matrix (PETSc's SYM = 2, not told it is
      // definite): the pivots' signs then tell whether it is (INFOG(12)),
      // as CHOLMOD's failure does; null pivots are detected (ICNTL(24)) so
      // that a singular matrix is refused, not solved.
      check(MatMumpsSetIcntl(factor, 24, 1), "MatMumpsSetIcntl");
      MatFactorInfo info;
      check(MatFactorInfoInitialize(&info), "MatFactorInfoInitialize");
      check(MatCholeskyFactorSymbolic(factor, matrix, nullptr, &info),
            "the analysis");
      // INFO(15): MUMPS's estimate of the memory this rank's factorisation
      // takes [MB]; INFOG(16) the largest over the ranks. Checked before
      // it allocates, against this rank's share of the machine.
      PetscInt this_rank = 0, largest = 0, entries = 0;
      check(MatMumpsGetInfo(factor, 15, &this_rank), "MatMumpsGetInfo");
      check(MatMumpsGetInfog(factor, 16, &largest), "MatMumpsGetInfog");
      check(MatMumpsGetInfog(factor, 20, &entries), "MatMumpsGetInfog");
      PetscReal elimination_flops = 0;
      check(MatMumpsGetRinfog(factor, 1, &elimination_flops),
            "MatMumpsGetRinfog");
      estimated_MB = this_rank;
      // INFOG(20) counts in millions when negative (MUMPS's convention).
      factor_entries = entries < 0 ? -1e6 * entries : double(entries);
      flops          = elimination_flops;
      std::string  limit;
      const double available = memory::available(limit) / 1e6;
      const double least =
        Utilities::MPI::min(available, parallel::communicator());
      std::ostringstream message;
      message << "out of memory: MUMPS's factor needs about " << largest
              << " MB on a rank, " << least
              << " MB are available on the rank with least (" << limit
              << "); use more ranks, Contact/Solver = iterative or a "
                 "coarser mesh";
      AssertThrow(largest < 0.8 * least, ExcMessage(message.str()));
      analysed = true;
    }



    bool
    MumpsFactor::factorise(const SparseMatrix<double> &a)
    {
      set_rows(a);
      if (!analysed)
        analyse();
      MatFactorInfo info;
      check(MatFactorInfoInitialize(&info), "MatFactorInfoInitialize");
      check(MatCholeskyFactorNumeric(factor, matrix, &info),
            "the factorisation");
      MatFactorError error = MAT_FACTOR_NOERROR;
      check(MatFactorGetError(factor, &error), "MatFactorGetError");
      PetscInt negative = 0, null_pivots = 0, used = 0;
      check(MatMumpsGetInfog(factor, 12, &negative), "MatMumpsGetInfog");
      check(MatMumpsGetInfog(factor, 28, &null_pivots), "MatMumpsGetInfog");
      check(MatMumpsGetInfo(factor, 22, &used), "MatMumpsGetInfo");
      used_MB = used;
      return error == MAT_FACTOR_NOERROR && negative == 0 && null_pivots == 0;
    }



    void
    MumpsFactor::solve(std::vector<double> &b)
    {
      PetscScalar *own = nullptr;
      check(VecGetArray(rhs, &own), "VecGetArray");
      std::copy(b.begin() + first, b.begin() + last, own);
      check(VecRestoreArray(rhs, &own), "VecRestoreArray");
      check(MatSolve(factor, rhs, x), "the solve");
      check(VecScatterBegin(gather, x, whole, INSERT_VALUES, SCATTER_FORWARD),
            "VecScatterBegin");
      check(VecScatterEnd(gather, x, whole, INSERT_VALUES, SCATTER_FORWARD),
            "VecScatterEnd");
      const PetscScalar *all = nullptr;
      check(VecGetArrayRead(whole, &all), "VecGetArrayRead");
      std::copy(all, all + b.size(), b.begin());
      check(VecRestoreArrayRead(whole, &all), "VecRestoreArrayRead");
    }
  } // namespace



  std::unique_ptr<SparseFactor>
  make_mumps_factor(const SparsityPattern &pattern)
  {
    return std::make_unique<MumpsFactor>(pattern);
  }
} // namespace knee_contact
