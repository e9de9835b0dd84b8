#include <knee_contact/core/memory.h>

#include <sys/resource.h>

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <utility>

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
    available(std::string &which)
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
      take(read_field("/proc/meminfo", "MemAvailable:", 1024.), "MemAvailable");
      for (const auto &[limit, usage] :
           {std::pair<std::string, std::string>{
              "/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"},
            {"/sys/fs/cgroup/memory/memory.limit_in_bytes",
             "/sys/fs/cgroup/memory/memory.usage_in_bytes"}})
        {
          const double max = read_number(limit), used = read_number(usage);
          if (max >= 0 && max < 1e18 && used >= 0)
            take(std::max(0., max - used), "the cgroup's memory limit");
        }
      rlimit address_space;
      if (getrlimit(RLIMIT_AS, &address_space) == 0 &&
          address_space.rlim_cur != RLIM_INFINITY)
        take(std::max(0., double(address_space.rlim_cur) - process_virtual()),
             "the address-space limit (ulimit -v)");
      return available;
    }



    double
    process_virtual()
    {
      return read_field("/proc/self/status", "VmSize:", 1024.);
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
