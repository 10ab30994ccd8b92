#include "mrpt_yesslam/place/VocabularyTraining.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "mrpt_yesslam/util/Error.h"

namespace fs = std::filesystem;

namespace mrpt_yesslam
{
namespace
{
bool isImageFile(const fs::path& p)
{
	auto ext = p.extension().string();
	std::transform(ext.begin(), ext.end(), ext.begin(),
				   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
	for (const char* e : {".png", ".jpg", ".jpeg", ".bmp", ".ppm", ".pgm", ".tif", ".tiff", ".webp"})
		if (ext == e) return true;
	return false;
}

// A folder is a sequence when it is a TUM RGB-D folder; anything else is searched for images.
bool isTumFolder(const fs::path& p)
{
	std::error_code ec;
	return fs::is_regular_file(p / "rgb.txt", ec) || fs::is_regular_file(p / "associations.txt", ec);
}

// An image file as a grey photograph; a 16-bit single-channel image is a depth map (TUM depth/
// PNGs beside the colour ones) and gives an empty matrix: it has no texture to learn words from.
cv::Mat readPhoto(const std::string& file)
{
	const cv::Mat raw = cv::imread(file, cv::IMREAD_UNCHANGED);
	if (raw.empty()) throw InputError(file, "cannot decode the image");
	if (raw.depth() == CV_16U && raw.channels() == 1) return {};
	return cv::imread(file, cv::IMREAD_GRAYSCALE);
}

double secondsSince(std::chrono::steady_clock::time_point t0)
{
	return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

std::vector<cv::Mat> collectTrainingDescriptors(const TVocabTrainingOptions& o,
												const std::function<void(std::size_t)>& progress,
												const std::function<bool()>& stop)
{
	if (o.inputs.empty()) throw InputError("", "no training input given");
	if (o.step < 1) throw InputError("", "the frame step must be at least 1");
	const COrbExtractor orb(o.orb);
	std::vector<cv::Mat> out;
	auto add = [&](const cv::Mat& img)
	{
		out.push_back(orb.extract(img).descriptors);
		if (progress) progress(out.size());
	};
	auto stopped = [&] { return stop && stop(); };
	for (const auto& in : o.inputs)
	{
		std::error_code ec;
		const fs::path p(in);
		if (!fs::exists(p, ec)) throw InputError(in, "not found");
		std::size_t taken = 0;
		auto full = [&] { return o.maxImagesPerInput && taken >= o.maxImagesPerInput; };
		if (fs::is_directory(p, ec) && !isTumFolder(p))
		{
			std::vector<fs::path> files;
			for (auto it = fs::recursive_directory_iterator(p, fs::directory_options::skip_permission_denied, ec);
				 !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
				if (it->is_regular_file(ec) && isImageFile(it->path())) files.push_back(it->path());
			if (files.empty())
				throw InputError(in, "no images (png, jpg, bmp, ppm, pgm, tif, webp) and no rgb.txt in this folder");
			const std::size_t before = out.size();
			std::sort(files.begin(), files.end());
			for (const auto& f : files)
			{
				if (full() || stopped()) break;
				const cv::Mat img = readPhoto(f.string());
				if (img.empty()) continue;
				add(img);
				taken++;
			}
			if (out.size() == before && !stopped())
				throw InputError(in, "only depth images (16-bit) in this folder, no photographs");
		}
		else if (fs::is_regular_file(p, ec) && isImageFile(p))
		{
			const cv::Mat img = readPhoto(in);
			if (img.empty())
				throw InputError(in, "a 16-bit single-channel image (a depth map) has no texture to train on");
			add(img);
		}
		else
		{
			auto src = openInputSource(in, o.source);
			std::size_t index = 0;
			while (!full() && !stopped())
			{
				const auto obs = src->next();
				if (!obs) break;
				if (index++ % o.step) continue;
				add(obs->intensityImage.asCvMatRef());
				taken++;
			}
			if (index == 0) throw InputError(in, "no frames");
		}
	}
	return out;
}

CVocabulary trainVocabulary(const TVocabTrainingOptions& o, TVocabTrainingSummary* summary,
							const std::function<void(const std::string&, std::size_t, std::size_t)>& progress,
							const std::function<bool()>& stop)
{
	TVocabTrainingSummary s;
	auto t0 = std::chrono::steady_clock::now();
	const auto descriptors = collectTrainingDescriptors(
		o,
		[&](std::size_t n)
		{
			if (progress) progress("extract", n, 0);
		},
		stop);
	s.interrupted = stop && stop();
	s.extractSeconds = secondsSince(t0);
	s.images = descriptors.size();  // replaced by the images that gave descriptors once trained
	for (const auto& d : descriptors) s.descriptors += static_cast<std::size_t>(d.rows);
	t0 = std::chrono::steady_clock::now();
	CVocabulary v = CVocabulary::train(descriptors, o.tree,
									   [&](std::size_t d, std::size_t t)
									   {
										   if (progress) progress("train", d, t);
									   });
	s.trainSeconds = secondsSince(t0);
	s.images = static_cast<std::size_t>(v.numTrainingImages());
	std::ostringstream desc;
	desc << "k=" << o.tree.branching << " L=" << o.tree.levels << " seed=" << o.tree.seed << "; "
		 << v.numTrainingImages() << " images, " << s.descriptors << " descriptors from " << o.inputs.size()
		 << " inputs; ORB numFeatures=" << o.orb.numFeatures << " numLevels=" << o.orb.numLevels
		 << " scaleFactor=" << o.orb.scaleFactor << " fastThreshold=" << o.orb.fastThreshold;
	v.setDescription(desc.str());
	if (summary) *summary = s;
	return v;
}
}  // namespace mrpt_yesslam
