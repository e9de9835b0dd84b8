#include <knee_contact/base/input.h>
#include <knee_contact/base/interruption.h>
#include <knee_contact/base/parallel.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/multithread_info.h>

#include <dlfcn.h>
#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <streambuf>
#include <thread>

namespace knee_contact
{
  namespace parallel
  {
    namespace
    {
      /**
       * Wait for @p request, polling every 10 ms instead of spinning in
       * MPI's progress loop (which takes a core from the work a waiting
       * rank waits for), until it completes or @p give_up says so. Whether
       * it completed.
       */
      bool
      wait_asleep(MPI_Request &request, const std::function<bool()> &give_up)
      {
        int arrived = 0;
        while (true)
          {
            MPI_Test(&request, &arrived, MPI_STATUS_IGNORE);
            if (arrived || give_up())
              return arrived;
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
          }
      }

      bool
      initialised()
      {
        int flag = 0;
        MPI_Initialized(&flag);
        int finalised = 0;
        MPI_Finalized(&finalised);
        return flag != 0 && finalised == 0;
      }

      /** Where a quiet rank's output goes. */
      class Sink : public std::streambuf
      {
      protected:
        int
        overflow(int c) override
        {
          return traits_type::not_eof(c);
        }
      };

      Sink            sink;
      std::streambuf *cerr_buffer = nullptr;
      /** Counted once at the start (a collective operation: memory checks
       * are made by one rank alone, when it writes the results). */
      unsigned int ranks_sharing_memory = 1;
      /** On rank 0 inside on_first_rank()'s work. */
      bool alone = false;
    } // namespace



    bool
    launched_by_mpirun()
    {
      for (const char *variable :
           {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "PMI_RANK"})
        if (std::getenv(variable) != nullptr)
          return true;
      return false;
    }



    /**
     * Trilinos' Epetra objects need MPI; a lone process initialises it
     * only when the iterative path is taken (and finalises it at exit).
     *
     * A process not started by mpirun is an Open MPI "singleton". By
     * default it forks a daemon (orted) and keeps a session folder under
     * TMPDIR (ompi.<host>.<uid>/jf.<n>) that only MPI_Finalize removes: a
     * run stopped by a signal, whose handler must _exit, left one folder
     * per run in /tmp (measured). So a singleton runs isolated (no daemon)
     * with its session folder inside a private folder of its own, which
     * the interruption handler removes on a signal and the exit handler
     * after MPI_Finalize. Only a SIGKILL can leave it. Under mpirun the
     * launcher owns the session.
     */
    void
    ensure_initialised()
    {
      int flag = 0;
      MPI_Initialized(&flag);
      if (flag)
        return;
      static std::string session_folder;
      if (!launched_by_mpirun())
        {
          // Open MPI's shared-memory and network transports would map
          // memory and plugins (and fail under an address-space limit,
          // measured), so only its "self" transport is loaded unless the
          // user chose otherwise.
          setenv("OMPI_MCA_btl", "self", 0);
          setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
          if (std::getenv("OMPI_MCA_orte_tmpdir_base") == nullptr)
            {
              const char *tmpdir = std::getenv("TMPDIR");
              std::string pattern =
                (tmpdir != nullptr && tmpdir[0] == '/' ? tmpdir : "/tmp");
              pattern += "/knee_contact-mpi-XXXXXX";
              if (mkdtemp(pattern.data()) != nullptr)
                {
                  session_folder = pattern;
                  interruption::register_folder(session_folder);
                  setenv("OMPI_MCA_orte_tmpdir_base",
                         session_folder.c_str(),
                         1);
                }
            }
        }
      int provided = 0;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
      MPI_Comm shared;
      MPI_Comm_split_type(
        MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &shared);
      int size = 1;
      MPI_Comm_size(shared, &size);
      MPI_Comm_free(&shared);
      ranks_sharing_memory = size;
      // The ranks of one machine share its cores: each threads its
      // replicated work (WorkStream's assembly, recovery, output) over its
      // share, as deal.II's MPI_InitFinalize does (DEAL_II_NUM_THREADS
      // still lowers it). With every rank on all cores, two ranks of the
      // 3D knee at 1.0e6 DoFs took 12.2 s for the assembly one process does
      // in 6.4 (2026-11-27).
      // The same for OpenBLAS's threads, which MUMPS's and CHOLMOD's
      // dense kernels run on (OPENBLAS_NUM_THREADS is read when the
      // library loads, before this).
      if (size > 1)
        {
          const unsigned int share =
            std::max(1u, dealii::MultithreadInfo::n_cores() / size);
          dealii::MultithreadInfo::set_thread_limit(share);
          // A rank of one thread takes glibc's one heap (arena): memory
          // freed by one part of the run (the whole mesh, the set-up's
          // patterns) is what the next allocates, where threads' own
          // arenas keep theirs. Measured on the 3D knee at 232 989 DoFs
          // (2026-12-02): rank 0's peak on two ranks 838 -> 753 MB, the
          // times within the machine's noise. (Not for a process of
          // several threads: one process at that size lost 10-15 % of
          // its solve and error-bar times to the shared lock for 110 MB.)
          if (share == 1)
            mallopt(M_ARENA_MAX, 1);
          using set_threads = void (*)(int);
          if (const auto set = reinterpret_cast<set_threads>(
                dlsym(RTLD_DEFAULT, "openblas_set_num_threads")))
            set(static_cast<int>(share));
        }
      std::atexit([]() {
        int finalised = 0;
        MPI_Finalized(&finalised);
        if (!finalised)
          MPI_Finalize();
        if (!session_folder.empty())
          {
            std::error_code ignored;
            std::filesystem::remove_all(session_folder, ignored);
            interruption::unregister_folder(session_folder);
          }
      });
    }



    MPI_Comm
    communicator()
    {
      return initialised() ? MPI_COMM_WORLD : MPI_COMM_SELF;
    }



    unsigned int
    n_ranks()
    {
      if (!initialised())
        return 1;
      int size = 1;
      MPI_Comm_size(MPI_COMM_WORLD, &size);
      return size;
    }



    unsigned int
    rank()
    {
      if (!initialised())
        return 0;
      int rank = 0;
      MPI_Comm_rank(MPI_COMM_WORLD, &rank);
      return rank;
    }



    unsigned int
    ranks_on_this_machine()
    {
      return ranks_sharing_memory;
    }



    void
    quiet_other_ranks()
    {
      if (rank() == 0)
        return;
      std::cout.rdbuf(&sink);
      cerr_buffer = std::cerr.rdbuf(&sink);
      // What libraries print on standard output goes too (ML warned on
      // every rank of 40 on a 2D patch test). Standard error's descriptor
      // stays: a crash, a sanitizer's report, MPI's own errors.
      [[maybe_unused]] const auto *null =
        std::freopen("/dev/null", "w", stdout);
      interruption::say_nothing();
    }



    int
    finish(const int code, const std::string &message, const double seconds)
    {
      if (n_ranks() == 1)
        {
          if (!message.empty())
            std::cerr << message << std::endl;
          return code;
        }
      // Wait for the others without blocking: a rank stuck in a collective
      // operation never arrives. A rank that succeeded waits as long as
      // the others take (they do the same work).
      MPI_Request request;
      MPI_Ibarrier(MPI_COMM_WORLD, &request);
      const auto end = std::chrono::steady_clock::now() +
                       std::chrono::duration<double>(seconds);
      const bool arrived = wait_asleep(request, [&]() {
        return code != 0 && std::chrono::steady_clock::now() > end;
      });
      const auto say     = [&](const std::string &suffix) {
        if (cerr_buffer != nullptr)
          std::cerr.rdbuf(cerr_buffer);
        if (!message.empty())
          std::cerr << message << suffix << std::endl;
      };
      if (!arrived)
        {
          // Only this rank left the run: say why and end the others.
          say(" (rank " + std::to_string(rank()) + ")");
          MPI_Abort(MPI_COMM_WORLD, code);
        }
      // Every rank has ended: the lowest that failed speaks for all.
      const int mine  = code != 0 ? int(rank()) : int(n_ranks());
      int       first = mine;
      MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
      if (first == int(rank()))
        say("");
      return code;
    }



    void
    broadcast_from_first(std::string &bytes)
    {
      if (n_ranks() == 1)
        return;
      unsigned long long size = bytes.size();
      MPI_Request        request;
      MPI_Ibcast(&size, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD, &request);
      wait_asleep(request, []() { return false; });
      bytes.resize(size);
      const unsigned long long piece = 1ull << 30;
      for (unsigned long long start = 0; start < size; start += piece)
        MPI_Bcast(bytes.data() + start,
                  int(std::min(piece, size - start)),
                  MPI_CHAR,
                  0,
                  MPI_COMM_WORLD);
    }


    std::vector<char>
    scatter_from_first(
      const std::function<std::vector<char>(unsigned int)> &piece_for)
    {
      if (n_ranks() == 1)
        return piece_for(0);
      const unsigned long long piece = 1ull << 30;
      if (rank() == 0)
        {
          for (unsigned int r = 1; r < n_ranks(); ++r)
            {
              const std::vector<char> bytes = piece_for(r);
              unsigned long long      size  = bytes.size();
              MPI_Send(&size, 1, MPI_UNSIGNED_LONG_LONG, r, 0, MPI_COMM_WORLD);
              for (unsigned long long start = 0; start < size; start += piece)
                MPI_Send(bytes.data() + start,
                         int(std::min(piece, size - start)),
                         MPI_CHAR,
                         r,
                         0,
                         MPI_COMM_WORLD);
            }
          return piece_for(0);
        }
      unsigned long long size = 0;
      MPI_Request        request;
      MPI_Irecv(
        &size, 1, MPI_UNSIGNED_LONG_LONG, 0, 0, MPI_COMM_WORLD, &request);
      wait_asleep(request, []() { return false; });
      std::vector<char> bytes(size);
      for (unsigned long long start = 0; start < size; start += piece)
        MPI_Recv(bytes.data() + start,
                 int(std::min(piece, size - start)),
                 MPI_CHAR,
                 0,
                 0,
                 MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
      return bytes;
    }



    std::string
    on_first_rank(const std::function<std::string()> &work,
                  const std::string                  &what)
    {
      if (n_ranks() == 1)
        return work();
      // Rank 0's outcome: "value\n" and the value, or the kind of its
      // failure ("input" or "internal") and its line.
      std::string        outcome;
      std::exception_ptr failure;
      if (rank() == 0)
        {
          alone = true;
          try
            {
              outcome = "value\n" + work();
            }
          catch (const dealii::ExcMessage &exc)
            {
              std::ostringstream info;
              exc.print_info(info);
              outcome = "input\n" + input::one_line(info.str());
              failure = std::current_exception();
            }
          catch (const std::runtime_error &exc)
            {
              outcome = "input\n" + input::one_line(exc.what());
              failure = std::current_exception();
            }
          catch (...)
            {
              outcome = "internal\n";
              failure = std::current_exception();
            }
          alone = false;
        }
      broadcast_from_first(outcome);
      if (failure)
        std::rethrow_exception(failure);
      const auto        line = outcome.find('\n');
      const std::string kind = outcome.substr(0, line);
      if (kind == "value")
        return outcome.substr(line + 1);
      if (kind == "input")
        throw std::runtime_error(outcome.substr(line + 1));
      throw std::logic_error("rank 0 failed to " + what);
    }



    bool
    working_alone()
    {
      return alone;
    }
  } // namespace parallel
} // namespace knee_contact
