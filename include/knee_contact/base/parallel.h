#ifndef knee_contact_parallel_h
#define knee_contact_parallel_h

#include <deal.II/base/mpi.h>

#include <mpi.h>

#include <functional>
#include <string>
#include <type_traits>
#include <vector>

namespace knee_contact
{
  /**
   * The processes of a run. Started by mpirun (or mpiexec), every rank
   * reads the same scene, builds the same mesh and contact rows and runs
   * the same loop; the iterative path distributes its matrix, AMG
   * hierarchy and Krylov vectors over the ranks (IterativeContactSystem),
   * the direct paths run on every rank. Rank 0 alone prints and writes the
   * result folder; every rank takes the loop's decisions from the same
   * replicated data, so they agree without a message.
   *
   * A lone process (no mpirun) is rank 0 of 1 and initialises MPI only
   * when Trilinos needs it (ensure_initialised()).
   */
  namespace parallel
  {
    /** Whether mpirun started this process (Open MPI's, MPICH's or PMIx's
     * environment says so). */
    bool
    launched_by_mpirun();

    /**
     * Initialise MPI once (finalised at exit). A lone process runs as an
     * isolated singleton whose session folder is removed on a signal too.
     */
    void
    ensure_initialised();

    /** MPI_COMM_WORLD once initialised, else MPI_COMM_SELF. */
    MPI_Comm
    communicator();

    /** Number of ranks (1 for a lone process). */
    unsigned int
    n_ranks();

    /** This process's rank (0 for a lone process). */
    unsigned int
    rank();

    /**
     * Ranks sharing this machine's memory (MPI_Comm_split_type): the
     * memory a path may take is what the machine has divided by them.
     */
    unsigned int
    ranks_on_this_machine();

    /**
     * Ranks other than 0 print nothing: std::cout and std::cerr go to a
     * sink (a rank's own failure is printed by finish_failed()).
     */
    void
    quiet_other_ranks();

    /**
     * The end of a run on this rank with exit code @p code and, if it
     * failed, its one-line @p message. One rank: the message is printed.
     * Several: rank 0 prints its own; then every rank waits (at most
     * @p seconds) until all have ended. If they all did, each returns its
     * code (a failure of the replicated work, bad input say, happened on
     * every rank and is printed once). A rank that failed alone, while the
     * others wait in a collective operation, prints its message and ends
     * the whole run (MPI_Abort with its code): no rank hangs.
     */
    int
    finish(const int code, const std::string &message, const double seconds);

    /**
     * Rank 0's @p bytes on every rank (resized there), in pieces of at most
     * 1 GB (MPI counts are int). A rank waiting for rank 0 sleeps between
     * polls instead of spinning in MPI's progress loop, which took a core
     * from gmsh on a machine of fewer cores than ranks: the first piece is
     * sent as soon as rank 0 arrives, after work of any length (its gmsh).
     */
    void
    broadcast_from_first(std::string &bytes);

    /**
     * Rank 0's @p piece_for(r) on rank r: rank 0 makes each rank's piece
     * and sends it before it makes the next (one piece at a time in its
     * memory), in messages of at most 1 GB; the others wait asleep, as in
     * broadcast_from_first(). Returns this rank's piece; @p piece_for is
     * called on rank 0 only.
     */
    std::vector<char>
    scatter_from_first(
      const std::function<std::vector<char>(unsigned int)> &piece_for);

    /**
     * @p work done by rank 0 alone while the others wait asleep (as in
     * broadcast_from_first()), and its outcome on every rank: the string
     * it returned, or its failure thrown on every rank, so that a refusal
     * ends every rank alike and is printed once (rank 0 rethrows its own
     * exception; the others a std::runtime_error with its one line where
     * it was bad input, an ExcMessage or a std::runtime_error, else a
     * std::logic_error "rank 0 failed to @p what"). While @p work runs,
     * working_alone() is true on rank 0. One rank: @p work, as it is.
     */
    std::string
    on_first_rank(const std::function<std::string()> &work,
                  const std::string                  &what);
    /**
     * Whether this rank is inside on_first_rank()'s work: a step that
     * would share its work with the other ranks (gmsh's outcome, say)
     * does it here alone instead, since they are not there to take part.
     */
    bool
    working_alone();
    /**
     * Every rank's @p mine on every rank, one after the other in rank
     * order: the records a rank flattened into numbers (Gamma lines,
     * contact sides, C's line rows, the dofs' bodies and positions, the
     * error bars' extremes), which every rank then reads whole. One
     * MPI_Allgatherv into the result: deal.II's Utilities::MPI::all_gather
     * serialises and compresses each rank's vector (zlib) and returns the
     * pieces apart, so that the result was held twice beside the packed
     * bytes (C's line rows at 1e6 dofs: 2 x 210 MB a rank above the rows
     * themselves, doc/parallel.md). A collective call on @p comm.
     */
    template <typename T>
    std::vector<T>
    gather_on_every_rank(const MPI_Comm comm, const std::vector<T> &mine)
    {
      static_assert(std::is_trivially_copyable_v<T>,
                    "gathered as bytes: a type of numbers");
      const std::vector<unsigned long long> counts =
        dealii::Utilities::MPI::all_gather(
          comm, static_cast<unsigned long long>(mine.size()));
      // Counted in records of sizeof(T) bytes (MPI counts are ints).
      std::vector<int>   sizes(counts.size()), offsets(counts.size());
      unsigned long long total = 0;
      for (std::size_t r = 0; r < counts.size(); ++r)
        {
          AssertThrow(total + counts[r] <= 2147483647ull,
                      dealii::ExcMessage(
                        "more than 2^31 records to gather on every rank"));
          sizes[r]   = int(counts[r]);
          offsets[r] = int(total);
          total += counts[r];
        }
      std::vector<T> all(total);
      MPI_Datatype   record;
      MPI_Type_contiguous(int(sizeof(T)), MPI_BYTE, &record);
      MPI_Type_commit(&record);
      MPI_Allgatherv(mine.data(),
                     int(mine.size()),
                     record,
                     all.data(),
                     sizes.data(),
                     offsets.data(),
                     record,
                     comm);
      MPI_Type_free(&record);
      return all;
    }
  } // namespace parallel
} // namespace knee_contact

#endif
