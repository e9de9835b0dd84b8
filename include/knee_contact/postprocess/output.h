#ifndef knee_contact_output_h
#define knee_contact_output_h

#include <knee_contact/base/external_program.h>
#include <knee_contact/base/result_folder.h>
#include <knee_contact/contact/contact.h>
#include <knee_contact/physics/materials.h>
#include <knee_contact/postprocess/error_estimate.h>
#include <knee_contact/postprocess/results.h>
#include <knee_contact/solver/active_set.h>

#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The files of a run, in the output folder: solution.vtu, one
   * contact_<interface>.csv per interface and summary.json. All files of a
   * run go into a staging folder that replaces the output folder in one
   * step at the end (ResultFolder), so the folder never mixes two runs.
   */
  template <int dim>
  class OutputWriter
  {
  public:
    /**
     * Declare the subsection "Output", each entry bound to the member it
     * sets.
     */
    void
    add_parameters(ParameterHandler &prm);

    /**
     * After parsing: the default folder from @p scene_file's name, the
     * labels' points.
     */
    void
    check_parameters(const std::string &scene_file);

    /**
     * Lock the output folder and create the run's staging folder beside it
     * (ResultFolder); throw a one-line error if either is impossible.
     */
    void
    prepare();

    /**
     * Swap the complete result set in for the output folder's previous one.
     */
    void
    commit();

    /**
     * solution.vtu: displacement, stresses, contact and friction fields at
     * the vertices, material and body per cell, in pieces of at most
     * Output/Cells per VTU piece cells. Under mpirun every rank calls it:
     * piece i is built by rank i mod N and written by rank 0 (a multiple
     * of N pieces), so the ranks share the output's time.
     */
    void
    write_vtu(const DoFHandler<dim>           &dof_handler,
              const std::vector<unsigned int> &body_of_cell,
              const Vector<double>            &solution,
              const Materials<dim>            &materials,
              const ContactPairs<dim>         &pairs,
              const ContactSolution           &contact,
              const Results<dim>              &results) const;

    void
    write_contact_csv(const ContactInterfaces &interfaces,
                      const ContactPairs<dim> &pairs,
                      const Vector<double>    &solution,
                      const ContactSolution   &contact,
                      const Results<dim>      &results) const;

    /**
     * The data of the pictures: 2D cells.npy, every cell's material and body
     * id and, at its vertices (counter-clockwise), position, displacement
     * and tau_yy; 3D surface.npy, the same for every boundary face with von
     * Mises instead of tau_yy.
     */
    void
    write_cells(const DoFHandler<dim>           &dof_handler,
                const std::vector<unsigned int> &body_of_cell,
                const Vector<double>            &solution,
                const Results<dim>              &results) const;

    /**
     * Draw the pictures of scripts/@p script (Debian's python3 with
     * matplotlib) in the folder, e.g. plot_results.py: deformation, tau_yy
     * and contact pressure pictures; by the run's picture process
     * (scripts/pictures.py, started by prepare()), else by the script on
     * its own. Does nothing if pictures are off. Returns false, with the
     * script's last line in @p message, if it failed.
     */
    bool
    run_script(const std::string &script, std::string &message) const;

    /**
     * Write the following files (and pictures) into the folder @p name of
     * the result set, created now; "" for the result set itself. Load
     * cases write one such folder per case.
     */
    void
    set_subfolder(const std::string &name);

    /**
     * Write the file @p name into the run's staging folder.
     */
    void
    write_file(const std::string                         &name,
               const std::function<void(std::ostream &)> &write) const;

    /**
     * summary.json; @p solver names the linear solver and @p solver_figures
     * its phase times and sizes (section "solver").
     */
    void
    write_summary(const Results<dim>                         &results,
                  const ContactSolution                      &contact,
                  const Materials<dim>                       &materials,
                  const std::map<std::string, double>        &wall_times,
                  const std::string                          &solver,
                  const std::map<std::string, double>        &solver_figures,
                  const std::map<std::string, ErrorEstimate> &estimates) const;

    /**
     * Print a warning on the terminal and keep it for summary.json
     * ("warnings"): for what is suspicious but not refused.
     */
    void
    warn(const std::string &message);

    bool
    test_mode() const
    {
      return terminal_test;
    }

    const std::string &
    folder() const
    {
      return output_folder;
    }

    bool
    enabled() const
    {
      return write_files;
    }

    /**
     * Whether this rank takes part in writing the result sets: rank 0,
     * which writes them (enabled()), and under mpirun the other ranks,
     * which build their share of solution.vtu's pieces for it
     * (write_vtu()).
     */
    bool
    takes_part() const
    {
      return write_files || builds_pieces;
    }

  private:
    /** The path of @p name in the staging folder. */
    std::string
    staging(const std::string &name) const;

    /** The path @p name will have in the output folder, for messages. */
    std::string
    final_path(const std::string &name) const;

    /** "" or the current case's folder with a trailing '/'. */
    std::string subfolder;

    std::unique_ptr<ResultFolder> result_folder;
    /** The run's picture process (none if pictures are off). */
    mutable std::unique_ptr<HelperProcess>          picture_process;
    std::vector<std::string>                        warnings;
    double                                          picture_time_limit = 600;
    unsigned int                                    cells_per_piece    = 65536;
    std::string                                     output_folder;
    double                                          magnification = 10;
    bool                                            pictures      = true;
    std::vector<std::pair<std::string, Point<dim>>> labels;
    /** 'Labels' as the scene wrote them. */
    std::vector<std::pair<std::string, std::vector<double>>> label_entries;
    bool terminal_test = false;
    bool write_files   = true;
    /** A rank other than 0 of a run that writes files. */
    bool builds_pieces = false;
  };
} // namespace knee_contact

#endif
