// flexfit-viewer run headless on the demo scene, as a user would (xvfb-run, or EGL with no X
// server), and its screenshot checked against the scene it shows: size, not blank, the
// deformation zone's green on the rim, and the ball and the rim where the camera projects them.
#include "png_io.hpp"
#include "temp_dir.hpp"
#include "viewer_core.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

using namespace flexfit;
using namespace flexfit::viewer;

namespace {

constexpr int kWidth = 1280, kHeight = 800, kFrames = 20;  // 20 frames at 60 Hz: 0.333 s, in contact

std::string scenePath() { return std::string(FLEXFIT_EXAMPLES_DIR) + "/ball_torus.toml"; }

int run(const std::string& command) {
    const int status = std::system((command + " > /dev/null 2>&1").c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string viewerCommand(const std::filesystem::path& png, const std::string& mode) {
    return std::string(FLEXFIT_VIEWER) + " " + scenePath() + " " + mode + " --frames " + std::to_string(kFrames) +
           " --width " + std::to_string(kWidth) + " --height " + std::to_string(kHeight) + " --screenshot " + png.string();
}

Vec3 rgb(const Image& image, int x, int y) {
    const std::uint8_t* p = image.pixel(x, y);
    return Vec3(p[0], p[1], p[2]) / 255.0;
}

bool isBackground(const Vec3& c) { return (c - kBackground).cwiseAbs().maxCoeff() < 0.02; }
bool isZoneGreen(const Vec3& c) { return c.y() > 0.3 && c.y() > 2.0 * c.x() && c.y() > 2.0 * c.z(); }

// The fraction of a (2r+1)^2 window around a pixel that passes `test`.
template <class Test>
double fractionAround(const Image& image, const Eigen::Vector3d& at, int r, Test test) {
    int yes = 0, all = 0;
    for (int y = int(at.y()) - r; y <= int(at.y()) + r; ++y)
        for (int x = int(at.x()) - r; x <= int(at.x()) + r; ++x) {
            if (x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
            ++all;
            yes += test(rgb(image, x, y));
        }
    return all ? double(yes) / all : 0.0;
}

void checkDemoScreenshot(const std::filesystem::path& png) {
    const Image image = readPng(png);
    ASSERT_EQ(image.width, kWidth);
    ASSERT_EQ(image.height, kHeight);

    // The scene the viewer showed: the same session, the same camera, the same frames.
    Session session(loadScene(scenePath()));
    const Camera camera = initialCamera(session.world(), kWidth, kHeight);  // framed when loaded
    for (int f = 0; f < kFrames; ++f) session.advance(1.0 / 60.0);
    const World& w = session.world();
    ASSERT_FALSE(w.part(0).movingMasses().empty()) << "the scene should be in contact by now";

    // Not blank: parts cover a good share of the picture, in many colours.
    int background = 0;
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) background += isBackground(rgb(image, x, y));
    EXPECT_LT(background, kWidth * kHeight * 9 / 10);
    EXPECT_GT(background, kWidth * kHeight / 4);

    // The zone's green where the rim's moving masses project (some are hidden by the ball).
    int greenAtZone = 0, visibleZone = 0;
    for (Index m : w.part(0).movingMasses()) {
        const auto p = camera.project(w.part(0).worldPosition(m));
        if (!p) continue;
        const auto hit = pick(w, camera.rayThrough(p->x(), p->y()));
        if (!hit || hit->body != 0 || hit->distance < (w.part(0).worldPosition(m) - camera.eye()).norm() - 0.3) continue;
        ++visibleZone;
        greenAtZone += fractionAround(image, *p, 1, isZoneGreen) > 0.0;
    }
    ASSERT_GT(visibleZone, 10);
    EXPECT_GT(greenAtZone, visibleZone / 2) << greenAtZone << " of " << visibleZone;

    // Silhouettes: the ball's orange around its projected centre (offset from the overlays
    // drawn through it), the rim's blue at its front.
    const Vec3 ballCentre = w.centreOfMass(1);
    const Vec3 right = camera.view().block<1, 3>(0, 0).transpose();
    const auto ball = camera.project(ballCentre + 3.0 * right);
    ASSERT_TRUE(ball);
    EXPECT_GT(fractionAround(image, *ball, 4, [](const Vec3& c) { return c.x() > 0.3 && c.x() > c.y() && c.y() > c.z(); }), 0.6);
    // The rim's front, 40 degrees aside from the overlays drawn down the middle.
    const Vec3 towardEye = Eigen::AngleAxisd(0.7, Vec3::UnitY()) * Vec3(camera.eye().x(), 0.0, camera.eye().z()).normalized();
    const auto rimFront = camera.project(12.0 * towardEye);
    ASSERT_TRUE(rimFront);
    EXPECT_GT(fractionAround(image, *rimFront, 4, [](const Vec3& c) { return c.z() > 0.3 && c.z() > c.x(); }), 0.8);
    // And the background beyond the parts: the lower left, clear of the scene and the panels.
    const Eigen::Vector3d lowerLeft(kWidth * 0.18, kHeight * 0.85, 0.0);
    for (BodyId id = 0; id < w.bodyCount(); ++id) ASSERT_FALSE(pick(w, camera.rayThrough(lowerLeft.x(), lowerLeft.y())));
    EXPECT_GT(fractionAround(image, lowerLeft, 3, isBackground), 0.9);
}

}  // namespace

TEST(ViewerRender, XvfbScreenshotOfTheDemoInContact) {
    if (std::string(FLEXFIT_XVFB_RUN).empty()) GTEST_SKIP() << "xvfb-run not found (Debian package xvfb): not tested under Xvfb";
    const flexfit::testing::TempDir dir;
    const auto png = dir.path() / "xvfb.png";
    ASSERT_EQ(run(std::string(FLEXFIT_XVFB_RUN) + " -a -s '-screen 0 1280x800x24' " + viewerCommand(png, "--hidden")), 0);
    checkDemoScreenshot(png);
}

TEST(ViewerRender, EglScreenshotWithNoXServer) {
    const flexfit::testing::TempDir dir;
    const auto png = dir.path() / "egl.png";
    ASSERT_EQ(run("env -u DISPLAY " + viewerCommand(png, "--egl")), 0);
    checkDemoScreenshot(png);
}
