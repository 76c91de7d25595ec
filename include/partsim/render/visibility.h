// Which parts of an articulated object no camera sees: segmentation from ten views around it.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "partsim/physics/scene.h"

namespace partsim {

/// Names of the links of `object` that move on a joint and have visuals but show in none of ten
/// segmentation views around the object (five from above, starting at the front, which faces
/// world -y; four from below; one from the top), rendered at `image_size` pixels square with
/// `backend` ("rasterizer", "pathtracer" or "null"). Sets the scene's backend and adds a light;
/// the cameras it adds are removed again. Throws partsim::Error when the object has no mesh
/// visuals or a picture cannot be taken.
std::vector<std::string> FindHiddenMovingLinks(Scene& scene, const Articulation& object,
                                               const std::string& backend = "rasterizer",
                                               int image_size = 96);

/// FindHiddenMovingLinks with the backend and size bound, as QualityOptions::hidden_parts
/// takes it (partsim/assets/quality.h).
std::function<std::vector<std::string>(Scene&, const Articulation&)> HiddenMovingLinksFinder(
    const std::string& backend, int image_size);

}  // namespace partsim
