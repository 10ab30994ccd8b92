#include "mrpt_yesslam/sim/SimTextures.h"

#include <algorithm>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
cv::Mat makeClutterTexture(uint32_t seed, int size, const cv::Scalar& base, double density)
{
	std::mt19937 rng(seed);
	std::uniform_int_distribution<int> pos(0, size - 1), col(0, 255), small(2, std::max(3, size / 10));
	std::uniform_real_distribution<double> u(0, 1);
	cv::Mat t(size, size, CV_8UC3, base);
	auto colour = [&]()
	{
		// Mostly shades of the base colour, some strong accents: like printed matter on a surface.
		if (u(rng) < 0.3) return cv::Scalar(col(rng), col(rng), col(rng));
		const double k = 0.4 + 1.2 * u(rng);
		return cv::Scalar(std::min(255.0, base[0] * k), std::min(255.0, base[1] * k), std::min(255.0, base[2] * k));
	};
	const int shapes = static_cast<int>(density * size * size / 400);
	for (int i = 0; i < shapes; i++)
	{
		const cv::Point p(pos(rng), pos(rng));
		switch (rng() % 5)
		{
			case 0:
				cv::rectangle(t, cv::Rect(p.x, p.y, small(rng), small(rng)), colour(), u(rng) < 0.6 ? cv::FILLED : 1);
				break;
			case 1: cv::circle(t, p, small(rng) / 2 + 1, colour(), u(rng) < 0.5 ? cv::FILLED : 1, cv::LINE_AA); break;
			case 2:
			{
				// Short strokes (cables, edges, handwriting), not lines across the whole surface: those
				// made every wall a web of corners.
				const int reach = std::max(4, size / 8);
				std::uniform_int_distribution<int> d(-reach, reach);
				cv::line(t, p, p + cv::Point(d(rng), d(rng)), colour(), 1, cv::LINE_AA);
				break;
			}
			case 3:
			{
				std::string s;
				for (int k = 0; k < 3 + static_cast<int>(rng() % 6); k++) s += static_cast<char>('A' + rng() % 26);
				cv::putText(t, s, p, cv::FONT_HERSHEY_SIMPLEX, 0.3 + 0.5 * u(rng), colour(), 1, cv::LINE_AA);
				break;
			}
			default:
			{
				std::vector<cv::Point> poly;
				for (int k = 0; k < 3 + static_cast<int>(rng() % 3); k++)
					poly.emplace_back(p.x + small(rng) - size / 20, p.y + small(rng) - size / 20);
				cv::fillConvexPoly(t, poly, colour(), cv::LINE_AA);
			}
		}
	}
	// Fine grain, so that even plain-looking areas are not perfectly flat.
	cv::Mat noise(t.size(), CV_16SC3);
	cv::theRNG().state = seed + 1;  // randn uses OpenCV's RNG: seed it for determinism
	cv::randn(noise, cv::Scalar::all(0), cv::Scalar::all(6));
	cv::Mat t16;
	t.convertTo(t16, CV_16SC3);
	t16 += noise;
	t16.convertTo(t, CV_8UC3);
	return t;
}

std::vector<cv::Mat> loadPhotoTextures(const std::string& folder, int size)
{
	namespace fs = std::filesystem;
	std::error_code ec;
	if (!fs::is_directory(folder, ec)) throw InputError(folder, "textures folder not found");
	std::vector<std::string> files;
	for (const auto& e : fs::directory_iterator(folder, ec))
	{
		std::string ext = e.path().extension().string();
		std::transform(ext.begin(), ext.end(), ext.begin(),
					   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
		if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") files.push_back(e.path().string());
	}
	std::sort(files.begin(), files.end());
	std::vector<cv::Mat> out;
	for (const auto& f : files)
	{
		const cv::Mat img = cv::imread(f, cv::IMREAD_COLOR);
		if (img.empty() || img.cols < 32 || img.rows < 32) continue;
		cv::Mat r;
		cv::resize(img, r, cv::Size(size, size), 0, 0, cv::INTER_AREA);
		out.push_back(r);
	}
	if (out.empty()) throw InputError(folder, "no readable .png/.jpg images to use as textures");
	return out;
}
}  // namespace mrpt_yesslam
