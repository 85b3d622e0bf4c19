// Loads a robot from its URDF and prints its joints and limits.
// Usage: robot_info ROBOT.urdf
#include <iostream>

#include "kinograph/dynamics/model.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: robot_info ROBOT.urdf\n";
    return 2;
  }
  try {
    const kinograph::dynamics::Model model = kinograph::dynamics::Model::from_urdf_file(argv[1]);
    std::cout << "robot '" << model.name << "': " << model.nq() << " joints\n";
    for (const kinograph::dynamics::Body& body : model.bodies) {
      std::cout << "  " << body.joint_name << ": [" << body.limits.lower << ", "
                << body.limits.upper << "] rad, " << body.limits.velocity << " rad/s, "
                << body.limits.effort << " N·m\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "robot_info: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
