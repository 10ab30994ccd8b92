#pragma once
// A user callback the system's stages call on their own threads.
#include <atomic>
#include <functional>
#include <memory>

namespace mrpt_yesslam
{
/** A callback that may be set from any thread while a stage calls it (a viewer attached to a
 * running system, or detached from it): set() swaps the new one in at once; a call runs the one
 * that was set when it started, whole, even if it is replaced meanwhile. So a call may still be
 * running when set() returns: a callback owns what it uses (captures shared_ptrs, not a viewer's
 * `this`), or its owner waits for the stages (CYesSlamSystem::waitForMapping) before going away. */
template <typename... Args>
class CCallbackSlot
{
   public:
	using Function = std::function<void(Args...)>;
	/** Replaces the callback; an empty function removes it. */
	void set(Function f)
	{
		std::shared_ptr<const Function> next;
		if (f) next = std::make_shared<const Function>(std::move(f));
		std::atomic_store(&f_, std::move(next));
	}
	/** Calls the callback, if one is set (what it throws goes to the caller). */
	void operator()(Args... args) const
	{
		if (const auto f = std::atomic_load(&f_)) (*f)(args...);
	}

   private:
	std::shared_ptr<const Function> f_;  //!< read and written with std::atomic_load/store only
};
}  // namespace mrpt_yesslam
