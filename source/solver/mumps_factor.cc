#include <knee_contact/base/memory.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/solver/sparse_factor.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>

#include <dmumps_c.h>

#include <algorithm>
#include <limits>
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
    // MUMPS's phases (its JOB). Its control and information arrays are
    // numbered from 1 in its manual: id.icntl[k - 1] is ICNTL(k).
    constexpr int job_initialise = -1, job_end = -2, job_analyse = 1,
                  job_factorise = 2, job_solve = 3;

    /**
     * MUMPS called directly (dmumps_c), not through PETSc: PETSc's interface
     * passes a given pivot order only for a matrix held on one rank, and
     * Debian's MUMPS has neither METIS nor SCOTCH, so its own ordering is
     * PORD's (measured on the 3D knee at 64 803 dofs: 1.31e11 flops a
     * factorisation against 9.29e10 in the METIS order CHOLMOD's analysis
     * made, which is handed to MUMPS here: ICNTL(7) = 1). Each rank gives
     * its block of rows (upper triangle, distributed input: ICNTL(18) = 3);
     * the right hand side and the solution are whole on rank 0 (MUMPS's
     * host, which works too: PAR = 1) and the solution is broadcast.
     */
    class MumpsFactor : public SparseFactor
    {
    public:
      MumpsFactor(const SparsityPattern  &pattern,
                  const std::vector<int> &order);
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
      /** Run MUMPS's phase @p job; its error (INFOG(1) < 0) as a line. */
      void
      call(const int job, const char *what);

      /** MUMPS's last phase failed (INFOG(1) < 0): throw its line. */
      void
      check(const char *what) const;

      /** MUMPS's analysis in the given order; refuses a factor that would
       * not fit. */
      void
      analyse();

      DMUMPS_STRUC_C          id;
      MPI_Comm                comm;
      types::global_dof_index first = 0, last = 0;
      std::vector<MUMPS_INT>  rows, columns, perm_in;
      std::vector<double>     values;
      bool                    analysed = false;
      double estimated_MB = 0, used_MB = 0, factor_entries = 0, flops = 0;
    };



    MumpsFactor::MumpsFactor(const SparsityPattern  &pattern,
                             const std::vector<int> &order)
    {
      parallel::ensure_initialised();
      comm                 = parallel::communicator();
      const unsigned int N = parallel::n_ranks(), r = parallel::rank();
      const auto         n = pattern.n_rows();
      AssertThrow(n < std::size_t(std::numeric_limits<MUMPS_INT>::max()),
                  ExcMessage("MUMPS: more rows than its 32-bit indices hold"));
      first = n * r / N;
      last  = n * (r + 1) / N;
      // This rank's rows, upper triangle: MUMPS sums the entries it is
      // given, so each symmetric pair once.
      for (auto i = first; i < last; ++i)
        for (auto entry = pattern.begin(i); entry != pattern.end(i); ++entry)
          if (entry->column() >= i)
            {
              rows.push_back(static_cast<MUMPS_INT>(i + 1));
              columns.push_back(static_cast<MUMPS_INT>(entry->column() + 1));
            }
      values.resize(rows.size());
      if (r == 0)
        {
          // PERM_IN(i): the position of variable i in the pivot order.
          perm_in.resize(n);
          for (std::size_t position = 0; position < order.size(); ++position)
            perm_in[order[position]] = static_cast<MUMPS_INT>(position + 1);
        }

      id              = DMUMPS_STRUC_C();
      id.comm_fortran = static_cast<MUMPS_INT>(MPI_Comm_c2f(comm));
      id.par          = 1;
      id.sym          = 2;
      call(job_initialise, "initialisation");
      // Silent (failures come back as INFOG(1) and are said in one line).
      id.icntl[0] = id.icntl[1] = id.icntl[2] = -1;
      id.icntl[3]                             = 0;
      id.icntl[6]                             = 1; // ICNTL(7): given order
      id.icntl[11]                            = 1; // ICNTL(12): as given
      id.icntl[17]                            = 3; // ICNTL(18): distributed
      // ICNTL(24): null pivots detected, so that a singular matrix is
      // refused, not solved.
      id.icntl[23] = 1;
      // One dense right hand side and its solution, whole on the host
      // (ICNTL(20) = 0, ICNTL(21) = 0).
      id.icntl[19] = 0;
      id.icntl[20] = 0;
      id.nrhs      = 1;
      id.n         = static_cast<MUMPS_INT>(n);
      id.lrhs      = id.n;
      id.nnz_loc   = rows.size();
      id.irn_loc   = rows.data();
      id.jcn_loc   = columns.data();
      id.a_loc     = values.data();
      if (r == 0)
        id.perm_in = perm_in.data();
    }



    MumpsFactor::~MumpsFactor()
    {
      // Errors cannot be reported from a destructor; MUMPS frees its own.
      id.job = job_end;
      dmumps_c(&id);
    }



    void
    MumpsFactor::call(const int job, const char *what)
    {
      id.job = job;
      dmumps_c(&id);
      check(what);
    }



    void
    MumpsFactor::check(const char *what) const
    {
      const int code = id.infog[0];
      if (code >= 0)
        return;
      // -8, -9, -11, -12, -13, -14, -15, -17, -19, -20: a workspace or
      // memory of MUMPS's; the rest its own diagnostics.
      const bool memory =
        code <= -8 && code >= -20 && code != -10 && code != -16 && code != -18;
      AssertThrow(false,
                  ExcMessage(std::string(memory ? "out of memory: " : "") +
                             "MUMPS's " + what +
                             " failed (INFOG(1) = " + std::to_string(code) +
                             ", INFOG(2) = " + std::to_string(id.infog[1]) +
                             "); use Contact/Direct factor = CHOLMOD or "
                             "Contact/Solver = iterative"));
    }



    void
    MumpsFactor::analyse()
    {
      call(job_analyse, "analysis");
      // INFO(15): MUMPS's estimate of the memory this rank's factorisation
      // takes [MB]; INFOG(16) the largest over the ranks. Checked before
      // it allocates, against this rank's share of the machine.
      // MUMPS counts in millions of bytes, summary.json in MiB.
      estimated_MB = id.info[14] * 1e6 / 1048576.;
      // INFOG(20) counts in millions when negative (MUMPS's convention).
      factor_entries =
        id.infog[19] < 0 ? -1e6 * id.infog[19] : double(id.infog[19]);
      flops = id.rinfog[0];
      std::string  limit;
      const double least =
        Utilities::MPI::min(memory::available(limit) / 1e6, comm);
      std::ostringstream message;
      message << "out of memory: MUMPS's factor needs about " << id.infog[15]
              << " MB on a rank, " << least
              << " MB are available on the rank with least (" << limit
              << "); use more ranks, Contact/Solver = iterative or a "
                 "coarser mesh";
      AssertThrow(id.infog[15] < 0.8 * least, ExcMessage(message.str()));
      analysed = true;
    }



    bool
    MumpsFactor::factorise(const SparseMatrix<double> &a)
    {
      // The values in the order of the pattern's entries (the same
      // pattern: the constructor's walk).
      std::size_t k = 0;
      for (auto i = first; i < last; ++i)
        for (auto entry = a.begin(i); entry != a.end(i); ++entry)
          if (entry->column() >= i)
            values[k++] = entry->value();
      AssertThrow(k == values.size(), ExcInternalError());
      if (!analysed)
        analyse();
      id.job = job_factorise;
      dmumps_c(&id);
      // -10: numerically singular, i.e. not definite here (the caller's
      // message); any other failure is said by check().
      if (id.infog[0] == -10)
        return false;
      check("factorisation");
      // INFO(22): the memory this rank used [millions of bytes].
      used_MB = id.info[21] * 1e6 / 1048576.;
      // INFOG(12): negative pivots; INFOG(28): null pivots.
      return id.infog[11] == 0 && id.infog[27] == 0;
    }



    void
    MumpsFactor::solve(std::vector<double> &b)
    {
      // b is whole on every rank; MUMPS reads and overwrites rank 0's
      // (the constructor's ICNTL(20), ICNTL(21)).
      id.rhs = parallel::rank() == 0 ? b.data() : nullptr;
      call(job_solve, "solve");
      MPI_Bcast(b.data(), static_cast<int>(b.size()), MPI_DOUBLE, 0, comm);
    }
  } // namespace



  std::unique_ptr<SparseFactor>
  make_mumps_factor(const SparsityPattern  &pattern,
                    const std::vector<int> &order)
  {
    return std::make_unique<MumpsFactor>(pattern, order);
  }
} // namespace knee_contact
