// Graph colouring of the contact constraints for the soft step: constraints
// of one colour share no moving body, so a colour's constraints may be
// solved in any order, on any thread, with the same result. Greedy, in the
// constraints' order (Box2D v3 colours its constraint graph the same way):
// each takes the first colour in which neither of its moving bodies is
// used yet; bodies that do not move (static, asleep) join any number of
// constraints of a colour, since nothing writes them. A constraint that
// finds no free colour among kMaxColours goes to the overflow set, solved
// after the colours on one thread.
#ifndef RIGID_BODY_SIM_PHYSICS_SOLVER_CONSTRAINT_COLOURING_H_
#define RIGID_BODY_SIM_PHYSICS_SOLVER_CONSTRAINT_COLOURING_H_

#include <cstdint>
#include <vector>

namespace rigid_body_sim::physics {

struct ConstraintColouring {
  // Colours of at most 64 fit one mask word per body.
  static constexpr int kMaxColours = 24;

  // The constraint indices of each colour, each colour in constraint order,
  // then those of the overflow set.
  std::vector<std::uint32_t> order;
  // Colour c holds order[colour_start[c], colour_start[c + 1]); the
  // overflow set is order[colour_start.back(), order.size()).
  std::vector<std::uint32_t> colour_start;

  int colour_count() const { return static_cast<int>(colour_start.size()) - 1; }
  std::size_t overflow_count() const { return order.size() - colour_start.back(); }
};

// Colours constraints i = 0..n-1 between bodies body_a[i] and body_b[i];
// moving[b] is nonzero for a body the solve writes. `used` is scratch,
// one word per body, kept by the caller so that a step allocates nothing.
void ColourConstraints(const std::vector<std::uint32_t>& body_a,
                       const std::vector<std::uint32_t>& body_b,
                       const std::vector<std::uint8_t>& moving, std::vector<std::uint32_t>* used,
                       std::vector<std::uint8_t>* colour_of, ConstraintColouring* colouring);

}  // namespace rigid_body_sim::physics

#endif  // RIGID_BODY_SIM_PHYSICS_SOLVER_CONSTRAINT_COLOURING_H_
