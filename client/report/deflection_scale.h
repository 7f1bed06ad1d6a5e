// A drawing with its flexible links' deflection magnified, for the eye: a
// link bending 13 micrometres on a 0.3 m coupler is drawn straight at any
// page size. Each centre line (SceneDrawing::Line: a straight, uniform link
// when undeformed, its points evenly spaced between its ends) keeps its
// ends where the analysis puts them; every inner point's offset from where
// it would sit on the straight line between them is drawn `scale` times
// its size, at every instant. The drawing's note says so. Scale 1 gives
// the drawing back unchanged, bit for bit. Pure.
#pragma once

#include <string>

#include "spec/scene_drawing.h"

namespace mbopt::report {

// `scale` must be finite and positive.
spec::SceneDrawing MagnifyDeflection(spec::SceneDrawing drawing, double scale);

// The scale a command line gives (`--deflection-scale K`): false unless
// `text` is all a finite, positive number.
bool ParseDeflectionScale(const std::string& text, double* scale);

}  // namespace mbopt::report
