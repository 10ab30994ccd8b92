#include "mrpt_yesslam/data/TFeatures.h"

#include <algorithm>

namespace mrpt_yesslam
{
std::size_t TFeatures::numStatic() const
{
	return static_cast<std::size_t>(std::count(dynamic.begin(), dynamic.end(), false));
}
}  // namespace mrpt_yesslam
