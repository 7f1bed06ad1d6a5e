// What the fuzzing targets check on every input, shared with the regression
// test that replays the seeds and every input a fuzzer ever found (so a
// finding stays fixed in the ordinary build). Each function returns quietly
// when the input is handled as it should be (accepted, or refused with an
// InvalidArgument that names the source), and aborts with a message when it
// is not: a crash, an unexpected status, or two validation paths that
// disagree on the same study.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace mbopt::fuzz {

// A study file's text (scene inline): the file path of `mbopt validate`,
// `submit`, `run` and `mbopt-worker eval`, then the server's path for the
// message the client would send, then the layout (limits, memory estimate).
void CheckStudyText(std::string_view data);

// A scene file's text.
void CheckSceneText(std::string_view data);

// A binary mbopt.v1.Study, as a hostile client could send it to the server.
void CheckStudyBinary(std::string_view data);

// A result's packed values (common/packed_doubles), as a hostile worker
// could send them: unpacked or refused with InvalidArgument, within the
// caller's bound; what unpacks packs again to the identical values.
void CheckPackedValues(std::string_view data);

// Packings the packed_values target starts from: smooth rows as a study
// makes them, random bit patterns, special values, nothing.
std::vector<std::string> PackedValuesSeeds();

}  // namespace mbopt::fuzz
