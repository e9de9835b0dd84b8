#ifndef knee_contact_progress_h
#define knee_contact_progress_h

#include <ostream>
#include <string>
#include <vector>

namespace knee_contact
{
  /**
   * Progress of a long run for the person at the terminal: after each step
   * of a sequence (a refinement cycle, a load case) one line with the time
   * since the run started and an estimate of the time left, and the time
   * since the start on each active-set iteration's line. Silent unless
   * standard output is a terminal and the run is not in test mode, so no
   * test output and no log file changes.
   */
  class Progress
  {
  public:
    /**
     * @p what names a step ("cycle", "load case"); @p n_steps is their
     * number (at most, where a target accuracy may stop early);
     * @p steps_grow says whether a step costs more than the one before
     * (refinement cycles) or about the same (load cases); the line names
     * step k as the run's other lines do, @p first_number + k.
     */
    Progress(std::ostream      &out,
             const std::string &what,
             const unsigned int n_steps,
             const bool         steps_grow,
             const unsigned int first_number);

    /**
     * Step @p step (from 0) is done after @p seconds. The time left: steps
     * of equal cost at their mean; growing steps at the last one's cost
     * grown by the ratio of the last two per step (clamped to [1, 10]), no
     * estimate after the first.
     */
    void
    step_done(const unsigned int step, const double seconds);

    /**
     * " [12.3 s]": the time since the run started, for a line on @p out,
     * or "" where progress is not shown.
     */
    static std::string
    stamp(const std::ostream &out);

    /** Whether @p out is standard output on a terminal. */
    static bool
    shown_on(const std::ostream &out);

    /** Start the run's clock (main(), before the scene is read). */
    static void
    start_clock();

  private:
    std::ostream       &out;
    std::string         what;
    unsigned int        n_steps;
    bool                steps_grow;
    unsigned int        first_number;
    std::vector<double> times;
  };
} // namespace knee_contact

#endif
