#pragma once
// Where the files shipped in share/mrpt_yesslam are at run time (detector model, vocabulary,
// configurations), for a build tree, an installed copy and a program that links the library.
#include <string>

namespace mrpt_yesslam
{
/** The share/mrpt_yesslam folder, the first that exists of: $YESSLAM_SHARE_DIR; the folder a
 * program gave setShareDir(); share/mrpt_yesslam in the folder of the binary holding this library
 * (the shared library, else the executable) or one of its three parents (an install: bin/ or
 * lib/<arch>/ beside share/; a build tree: its share/ link); the install prefix it was built for.
 * Empty when none exists. Never the source tree: an installed program must not depend on it. */
std::string shareDir();

/** Makes `dir` the share folder for this process (after $YESSLAM_SHARE_DIR): for programs linking
 * an installed package that has moved since it was built; the package's CMake config gives the
 * folder as MRPT_YESSLAM_SHARE_DIR. Empty restores the search. */
void setShareDir(const std::string& dir);
}  // namespace mrpt_yesslam
