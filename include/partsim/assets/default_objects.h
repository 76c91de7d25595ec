// Procedural objects that need no asset files: a cabinet with a drawer and a door, written as a
// URDF string made only of boxes and cylinders. It is the CLI's embedded default object and a
// small test object for tasks and benchmarks.
#pragma once

#include <cstdint>
#include <string>

namespace partsim {

/// Sizes and physical parameters of the generated cabinet. Frame of the cabinet ("body" link):
/// origin at the centre of its bottom face, x pointing out of the front, z up.
///
/// Layout: an outer body (back, two sides, top, bottom) split by a horizontal shelf divider; the
/// upper compartment holds one drawer ("drawer_0", prismatic along +x), the lower one is closed
/// by a door ("door_0", revolute about a vertical hinge at the front of one side).
struct CabinetOptions {
  double height = 0.8;            ///< outer height (m), > 0
  double width = 0.6;             ///< outer width, along y (m), > 0
  double depth = 0.5;             ///< outer depth, along x (m), > 0
  double wall_thickness = 0.018;  ///< thickness of every wall and panel (m), > 0
  /// Height of the drawer compartment as a fraction of the inner height, in (0.1, 0.9).
  double drawer_fraction = 0.3;
  double drawer_travel = 0.4;      ///< upper limit of the drawer joint (m), <= inner depth
  double door_limit = 1.6;         ///< upper limit of the door joint (rad), in (0, pi]
  bool door_hinge_left = false;    ///< hinge on the +y side (left, seen from the front)
  double handle_radius = 0.01;     ///< radius of the handle bars (m)
  double handle_length = 0.16;     ///< length of the handle bars between post centres (m)
  double handle_offset = 0.04;     ///< distance from the panel's front face to the bar axis (m)
  double wood_density = 600.0;     ///< kg/m^3 for walls, drawer and door
  double handle_density = 2700.0;  ///< kg/m^3 for handles (aluminium)
  double joint_friction = 0.1;     ///< dry friction of both joints (N or N m)
  double joint_damping = 0.5;      ///< viscous damping of both joints (N s/m or N m s/rad)
  /// 0 keeps the sizes above; any other value scales height, width, depth (and with it the
  /// drawer travel) and the drawer fraction by deterministic pseudo-random factors within +-15%,
  /// and picks the hinge side.
  std::uint32_t seed = 0;
  std::string name = "cabinet";  ///< robot name in the URDF
};

/// Writes the cabinet described by `opts` as a URDF string with three links ("body",
/// "drawer_0", "door_0") and two joints ("drawer_0_joint" prismatic, "door_0_joint" revolute).
/// Each link carries an explicit <inertial> computed from its shapes and densities. Visual names
/// follow PartNet-Mobility ("handle-drawer_0", "handle-door_0", "panel-door_0", ...). Throws
/// partsim::Error naming the option when a size is out of range.
std::string MakeCabinetUrdf(const CabinetOptions& opts = CabinetOptions());

}  // namespace partsim
