#pragma once
// Pictures through the matplotlib scripts of scripts/ (plot_curve, plot_stability, plot_sweep,
// draw): one helper, so that a missing interpreter or a failed script is reported the same way
// by every command. A picture is a by-product: its failure is a warning on stderr and never
// changes the exit status of the numerical result.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace voussoir {

// Runs `python3 scripts/SCRIPT ARGS...` (the source tree's scripts). On failure prints
// "voussoir: warning: OUTPUT could not be drawn: WHY" (WHY: no /usr/bin/python3, or the
// script's exit status) and returns false.
bool draw_with_script(const std::string& script, const std::vector<std::string>& args,
                      const std::string& output);

// Draws `geometry` (model_geometry_json or failure_mode_json, with "thrust" lines) to
// `picture` through scripts/draw, passing `args` after the output: the JSON goes to a file
// beside the picture for the time of the drawing.
bool draw_geometry(const nlohmann::json& geometry, const std::string& picture,
                   const std::vector<std::string>& args);

}  // namespace voussoir
