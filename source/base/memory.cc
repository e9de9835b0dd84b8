#include <knee_contact/base/memory.h>
#include <knee_contact/base/parallel.h>

#include <dlfcn.h>
#include <sys/resource.h>
#ifdef __GLIBC__
#  include <malloc.h>
#endif

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

namespace knee_contact
{
  namespace memory
  {
    namespace
    {
      /** The first number after @p key in @p file [bytes], or -1. */
      double
      read_field(const std::string &file, const std::string &key, double unit)
      {
        std::ifstream in(file);
        std::string   line;
        while (std::getline(in, line))
          if (line.compare(0, key.size(), key) == 0)
            {
              std::istringstream fields(line.substr(key.size()));
              double             value = -1;
              if (fields >> value)
                return value * unit;
            }
        return -1;
      }

      /** A file holding one number ("max": no limit) [bytes], or -1. */
      double
      read_number(const std::string &file)
      {
        std::ifstream in(file);
        std::string   word;
        if (!(in >> word) || word == "max")
          return -1;
        try
          {
            return std::stod(word);
          }
        catch (...)
          {
            return -1;
          }
      }
    } // namespace



    double
    available(std::string &which, const bool address_space)
    {
      double available = std::numeric_limits<double>::max();
      which            = "no limit found";
      const auto take  = [&](const double value, const std::string &name) {
        if (value >= 0 && value < available)
          {
            available = value;
            which     = name;
          }
      };
      // Ranks of one run on this machine share its memory: each may take
      // its part (they hold about the same).
      const double ranks = parallel::ranks_on_this_machine();
      take(read_field("/proc/meminfo", "MemAvailable:", 1024.) / ranks,
           ranks > 1 ? "MemAvailable / " + std::to_string(int(ranks)) +
                         " ranks on this machine"
                     : "MemAvailable");
      for (const auto &[limit, usage] :
           {std::pair<std::string, std::string>{
              "/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"},
            {"/sys/fs/cgroup/memory/memory.limit_in_bytes",
             "/sys/fs/cgroup/memory/memory.usage_in_bytes"}})
        {
          const double max = read_number(limit), used = read_number(usage);
          if (max >= 0 && max < 1e18 && used >= 0)
            take(std::max(0., max - used) / ranks, "the cgroup's memory limit");
        }
      if (address_space && address_space_limited())
        take(std::max(0., address_space_limit() - process_virtual()),
             "the address-space limit (ulimit -v)");
      return available;
    }



    double
    process_virtual()
    {
      return read_field("/proc/self/status", "VmSize:", 1024.);
    }



    double
    peak_resident_MB()
    {
      return read_field("/proc/self/status", "VmHWM:", 1. / 1024.);
    }



    void
    return_free_heap()
    {
#ifdef __GLIBC__
      malloc_trim(0);
#endif
    }



    double
    address_space_limit()
    {
      rlimit address_space;
      return getrlimit(RLIMIT_AS, &address_space) == 0 &&
                 address_space.rlim_cur != RLIM_INFINITY
               ? double(address_space.rlim_cur)
               : std::numeric_limits<double>::infinity();
    }



    bool
    address_space_limited()
    {
      return std::isfinite(address_space_limit());
    }



    void
    prepare_blas()
    {
      if (!address_space_limited())
        return;
      std::string  which;
      const double room = available(which);
      if (room < 2 * 128 * 1048576.)
        throw std::runtime_error(
          "out of memory: " + which + " leaves " + megabytes(room) +
          "; the linear algebra (OpenBLAS) alone needs 256 MB");
      using set_threads = void (*)(int);
      if (const auto set = reinterpret_cast<set_threads>(
            dlsym(RTLD_DEFAULT, "openblas_set_num_threads")))
        set(1);
      using gemm = void (*)(const char *,
                            const char *,
                            const int *,
                            const int *,
                            const int *,
                            const double *,
                            const double *,
                            const int *,
                            const double *,
                            const int *,
                            const double *,
                            double *,
                            const int *);
      if (const auto product =
            reinterpret_cast<gemm>(dlsym(RTLD_DEFAULT, "dgemm_")))
        {
          const int           n   = 128;
          const double        one = 1, zero = 0;
          std::vector<double> a(n * n, 1.), c(n * n);
          product("N",
                  "N",
                  &n,
                  &n,
                  &n,
                  &one,
                  a.data(),
                  &n,
                  a.data(),
                  &n,
                  &zero,
                  c.data(),
                  &n);
        }
    }



    std::string
    megabytes(const double bytes)
    {
      std::ostringstream out;
      out << std::fixed << std::setprecision(0) << bytes / 1048576. << " MB";
      return out.str();
    }
  } // namespace memory
} // namespace knee_contact
