#include <knee_contact/base/progress.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>

namespace knee_contact
{
  namespace
  {
    std::chrono::steady_clock::time_point &
    run_start()
    {
      static std::chrono::steady_clock::time_point start =
        std::chrono::steady_clock::now();
      return start;
    }

    double
    since_start()
    {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                           run_start())
        .count();
    }

    std::string
    seconds_text(const double seconds)
    {
      char text[32];
      if (seconds < 100)
        std::snprintf(text, sizeof(text), "%.1f s", seconds);
      else if (seconds < 6000)
        std::snprintf(text, sizeof(text), "%.1f min", seconds / 60);
      else
        std::snprintf(text, sizeof(text), "%.1f h", seconds / 3600);
      return text;
    }
  } // namespace



  Progress::Progress(std::ostream      &out,
                     const std::string &what,
                     const unsigned int n_steps,
                     const bool         steps_grow,
                     const unsigned int first_number)
    : out(out)
    , what(what)
    , n_steps(n_steps)
    , steps_grow(steps_grow)
    , first_number(first_number)
  {}



  void
  Progress::step_done(const unsigned int step, const double seconds)
  {
    times.push_back(seconds);
    if (!shown_on(out) || step + 1 >= n_steps)
      return;
    const unsigned int n_left = n_steps - step - 1;
    std::string        left;
    if (!steps_grow)
      {
        double sum = 0;
        for (const double t : times)
          sum += t;
        left = ", about " + seconds_text(sum / times.size() * n_left) + " left";
      }
    else if (times.size() >= 2)
      {
        const double previous = times[times.size() - 2];
        const double ratio =
          previous > 0 ? std::clamp(times.back() / previous, 1., 10.) : 1.;
        double estimate = 0, cost = times.back();
        for (unsigned int k = 0; k < n_left; ++k)
          estimate += (cost *= ratio);
        left = ", about " + seconds_text(estimate) + " left";
      }
    out << "-- " << what << " " << first_number + step << " done (" << step + 1
        << " of " << n_steps << "): " << seconds_text(since_start())
        << " elapsed" << left << std::endl;
  }



  std::string
  Progress::stamp(const std::ostream &out)
  {
    return shown_on(out) ? " [" + seconds_text(since_start()) + "]" : "";
  }



  bool
  Progress::shown_on(const std::ostream &out)
  {
    static const bool terminal = isatty(STDOUT_FILENO) == 1;
    return terminal && &out == &std::cout;
  }



  void
  Progress::start_clock()
  {
    run_start() = std::chrono::steady_clock::now();
  }
} // namespace knee_contact
