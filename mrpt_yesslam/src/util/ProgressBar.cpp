#include "mrpt_yesslam/util/ProgressBar.h"

#include <unistd.h>

#include <algorithm>

namespace mrpt_yesslam
{
ProgressBar::ProgressBar(std::string label, std::size_t total, bool enabled, std::string rateUnit)
	: label_(std::move(label)),
	  total_(total),
	  enabled_(enabled),
	  tty_(::isatty(STDERR_FILENO) != 0),
	  rateUnit_(std::move(rateUnit)),
	  start_(std::chrono::steady_clock::now()),
	  lastDraw_(start_)
{
}

void ProgressBar::startClock()
{
	start_ = std::chrono::steady_clock::now();
	stop_.reset();
}

void ProgressBar::stopClock()
{
	stop_ = std::chrono::steady_clock::now();
}

void ProgressBar::update(std::size_t done, const std::string& extra)
{
	done_ = done;
	if (!enabled_) return;
	const auto now = std::chrono::steady_clock::now();
	// Redraw at 10 Hz on a terminal, every 5 s in a log file.
	const auto period = tty_ ? std::chrono::milliseconds(100) : std::chrono::milliseconds(5000);
	if (now - lastDraw_ < period) return;
	lastDraw_ = now;
	draw(false, extra);
}

void ProgressBar::finish(const std::string& extra)
{
	if (!enabled_) return;
	draw(true, extra);
}

void ProgressBar::draw(bool final, const std::string& extra)
{
	const double secs =
		std::chrono::duration<double>(stop_.value_or(std::chrono::steady_clock::now()) - start_).count();
	const double rate = secs > 0 ? static_cast<double>(done_) / secs : 0.0;
	std::string line = label_ + " ";
	if (total_ > 0)
	{
		const double frac = std::min(1.0, static_cast<double>(done_) / static_cast<double>(total_));
		const int width = 30;
		const int filled = static_cast<int>(frac * width + 0.5);
		line += "[" + std::string(filled, '#') + std::string(width - filled, '.') + "] ";
		char buf[96];
		std::snprintf(buf, sizeof(buf), "%zu/%zu (%3.0f%%) %.1f%s", done_, total_, frac * 100.0, rate,
					  rateUnit_.c_str());
		line += buf;
		if (!final && rate > 0 && done_ < total_)
		{
			std::snprintf(buf, sizeof(buf), " eta %.0fs", static_cast<double>(total_ - done_) / rate);
			line += buf;
		}
	}
	else
	{
		char buf[64];
		std::snprintf(buf, sizeof(buf), "%zu done, %.1f%s", done_, rate, rateUnit_.c_str());
		line += buf;
	}
	if (!extra.empty()) line += " " + extra;
	if (tty_)
		std::fprintf(stderr, "\r\033[K%s%s", line.c_str(), final ? "\n" : "");
	else
		std::fprintf(stderr, "%s\n", line.c_str());
	std::fflush(stderr);
}
}  // namespace mrpt_yesslam
