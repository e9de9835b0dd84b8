#include <knee_contact/physics/elements.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_tools.h>

#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>

namespace knee_contact
{
  namespace elements
  {
    template <int dim>
    ReferenceCell
    cell_kind(const Triangulation<dim> &triangulation)
    {
      // MeshInput splits mixed meshes: two kinds here are a bug of the
      // program (exit code 4), not bad input.
      const auto kinds = triangulation.get_reference_cells();
      AssertThrow(kinds.size() == 1, ExcInternalError());
      return kinds[0];
    }



    template <int dim>
    std::unique_ptr<FiniteElement<dim>>
    displacement_element(const ReferenceCell &kind)
    {
      if (kind.is_simplex())
        return std::make_unique<FESystem<dim>>(FE_SimplexP<dim>(1), dim);
      return std::make_unique<FESystem<dim>>(FE_Q<dim>(1), dim);
    }



    template <int dim>
    void
    renumber_vertex_wise(DoFHandler<dim> &dof_handler)
    {
      // deal.II's DoFRenumbering::Cuthill_McKee() orders dofs, not
      // vertices: it does not keep a vertex's components together, and its
      // graph of every dof pair took 11.7 s at 1e6 dofs, this one 2.7 s
      // (the vertices' graph has a ninth of the entries). Measured on the
      // 3D knee at 1e6 dofs against the file's order (doc/parallel.md): a
      // CG iteration 0.79 -> 0.46 s on one process (the vectors' and the
      // matrix's accesses near each other), CG iterations 482 -> 387 on
      // one process and 260 -> 250 on two ranks (ML aggregates in row
      // order); at 2.3e5 dofs 185 -> 222 and 196 -> 189.
      const IndexSet &owned = dof_handler.locally_owned_dofs();
      AssertThrow(dof_handler.get_fe().n_dofs_per_cell() ==
                    dof_handler.get_fe().n_dofs_per_vertex() *
                      dof_handler.get_fe().reference_cell().n_vertices(),
                  ExcInternalError());
      const unsigned int none       = numbers::invalid_unsigned_int;
      const unsigned int components = dof_handler.get_fe().n_dofs_per_vertex();
      // The vertices of this rank's own dofs (a vertex's components have
      // one owner), numbered in the order their cells come, and their
      // dofs, component by component.
      std::vector<unsigned int> local(
        dof_handler.get_triangulation().n_vertices(), none);
      std::vector<types::global_dof_index> dofs;
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          for (const unsigned int v : cell->vertex_indices())
            if (local[cell->vertex_index(v)] == none &&
                owned.is_element(cell->vertex_dof_index(v, 0)))
              {
                local[cell->vertex_index(v)] = dofs.size() / components;
                for (unsigned int c = 0; c < components; ++c)
                  dofs.push_back(cell->vertex_dof_index(v, c));
              }
      // The graph of the vertices that share a cell (its size is known only
      // now, hence a second pass): a ninth of the entries of the dofs'
      // sparsity pattern, freed before that is made, so it never sets the
      // run's peak.
      const unsigned int        n_local = dofs.size() / components;
      DynamicSparsityPattern    graph(n_local);
      std::vector<unsigned int> mine;
      for (const auto &cell : dof_handler.active_cell_iterators())
        if (cell->is_locally_owned())
          {
            mine.clear();
            for (const unsigned int v : cell->vertex_indices())
              if (local[cell->vertex_index(v)] != none)
                mine.push_back(local[cell->vertex_index(v)]);
            for (const unsigned int a : mine)
              for (const unsigned int b : mine)
                graph.add(a, b);
          }
      std::vector<DynamicSparsityPattern::size_type> order(n_local);
      // (A rank without dofs of its own still takes part in
      // renumber_dofs(), which is collective.)
      if (n_local > 0)
        SparsityTools::reorder_Cuthill_McKee(graph, order);
      // order[k]: the place of local vertex k in Cuthill-McKee order. The
      // vertices' components take this rank's indices in the reverse of
      // that order (the textbook's choice; measured, doc/parallel.md: CG
      // iterations at 1e6 dofs 387 against Cuthill-McKee's 413 on one
      // process, 250 against 258 on two ranks).
      std::vector<unsigned int> at(n_local);
      for (unsigned int k = 0; k < n_local; ++k)
        at[n_local - 1 - order[k]] = k;
      AssertThrow(dofs.size() == owned.n_elements(), ExcInternalError());
      std::vector<types::global_dof_index> new_numbers(owned.n_elements());
      types::global_dof_index              next = 0;
      for (const unsigned int k : at)
        for (unsigned int c = 0; c < components; ++c)
          new_numbers[owned.index_within_set(dofs[k * components + c])] =
            owned.nth_index_in_set(next++);
      dof_handler.renumber_dofs(new_numbers);
    }



    std::string
    name(const ReferenceCell &kind)
    {
      return kind.is_simplex() ? "P1" : "Q1";
    }



    template ReferenceCell
    cell_kind(const Triangulation<2> &);
    template ReferenceCell
    cell_kind(const Triangulation<3> &);
    template void
    renumber_vertex_wise(DoFHandler<2> &);
    template void
    renumber_vertex_wise(DoFHandler<3> &);
    template std::unique_ptr<FiniteElement<2>>
    displacement_element<2>(const ReferenceCell &);
    template std::unique_ptr<FiniteElement<3>>
    displacement_element<3>(const ReferenceCell &);
  } // namespace elements
} // namespace knee_contact
