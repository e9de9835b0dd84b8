// Shared by the distributed tests: a scene run whole, its report (checked
// by the scene's own test) kept off the output.

#ifndef knee_contact_tests_run_quietly_h
#define knee_contact_tests_run_quietly_h

#include <knee_contact/core/problem.h>

#include <iostream>
#include <sstream>
#include <string>

template <int dim>
void
run_quietly(knee_contact::ContactProblem<dim> &problem,
            const std::string                 &scene)
{
  std::ostringstream report;
  std::streambuf    *out  = std::cout.rdbuf(report.rdbuf());
  const int          code = problem.run();
  std::cout.rdbuf(out);
  AssertThrow(code == 0, dealii::ExcMessage(scene + " failed"));
}

#endif
