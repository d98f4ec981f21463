#include "viewer_app.hpp"

#include "gl.hpp"

#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace flexfit::viewer {
namespace {

const char* kMaterials[] = {"rigid", "elastic", "superelastic"};

// The restoration methods in the vocabulary's order (names.hpp), by label, for the combo box.
const std::vector<const char*>& restorationLabels() {
    static const std::vector<const char*> labels = [] {
        std::vector<const char*> out;
        for (const auto& e : enumNames<RestorationMethod>()) out.push_back(e.label);
        return out;
    }();
    return labels;
}
RestorationMethod restorationAt(int index) { return enumNames<RestorationMethod>()[std::size_t(index)].value; }
int restorationIndex(RestorationMethod method) {
    const auto names = enumNames<RestorationMethod>();
    for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i].value == method) return int(i);
    return 0;
}

void addSegment(std::vector<LineVertex>& out, const Vec3& a, const Vec3& b, const Vec3& colour) {
    out.push_back(lineVertex(a, colour));
    out.push_back(lineVertex(b, colour));
}

void addBox(std::vector<LineVertex>& out, const Aabb& box, const Pose& pose, const Vec3& colour) {
    for (int e = 0; e < 12; ++e) {
        // The 12 edges: pairs of corners differing in one coordinate bit.
        const int axis = e / 4, rest = e % 4;
        int a = 0;
        for (int bit = 0, k = 0; bit < 3; ++bit)
            if (bit != axis) a |= ((rest >> k++) & 1) << bit;
        const int b = a | (1 << axis);
        auto corner = [&](int c) { return Vec3(c & 1 ? box.max.x() : box.min.x(), c & 2 ? box.max.y() : box.min.y(), c & 4 ? box.max.z() : box.min.z()); };
        addSegment(out, pose.apply(corner(a)), pose.apply(corner(b)), colour);
    }
}

void addCircle(std::vector<LineVertex>& out, const Vec3& centre, const Vec3& u, const Vec3& v, double radius, const Vec3& colour) {
    constexpr int kSegments = 48;
    for (int i = 0; i < kSegments; ++i) {
        const double a = 2 * M_PI * i / kSegments, b = 2 * M_PI * (i + 1) / kSegments;
        addSegment(out, centre + radius * (std::cos(a) * u + std::sin(a) * v), centre + radius * (std::cos(b) * u + std::sin(b) * v), colour);
    }
}

void addArea(std::vector<LineVertex>& out, const AssemblyArea& area, const Pose& secondary, const Vec3& colour) {
    const Pose frame = area.frame.then(secondary);
    const Vec3 x = frame.rotate(Vec3::UnitX()), y = frame.rotate(Vec3::UnitY()), z = frame.rotate(Vec3::UnitZ());
    const Vec3 c = frame.translation;
    switch (area.shape) {
        case AssemblyArea::Shape::Box: addBox(out, {-area.halfExtents, area.halfExtents}, frame, colour); break;
        case AssemblyArea::Shape::Sphere:
            addCircle(out, c, x, y, area.radius, colour);
            addCircle(out, c, y, z, area.radius, colour);
            addCircle(out, c, z, x, area.radius, colour);
            break;
        case AssemblyArea::Shape::Cylinder:
            addCircle(out, c + area.halfHeight * y, x, z, area.radius, colour);
            addCircle(out, c - area.halfHeight * y, x, z, area.radius, colour);
            for (int k = 0; k < 4; ++k) {
                const Vec3 side = area.radius * (k % 2 ? (k < 2 ? x : Vec3(-x)) : (k < 2 ? z : Vec3(-z)));
                addSegment(out, c + side + area.halfHeight * y, c + side - area.halfHeight * y, colour);
            }
            break;
    }
}

void addArrow(std::vector<LineVertex>& out, const Vec3& from, const Vec3& to, const Vec3& colour) {
    addSegment(out, from, to, colour);
    const Vec3 d = to - from;
    if (d.norm() < 1e-12) return;
    const Vec3 side = d.unitOrthogonal() * d.norm() * 0.08;
    addSegment(out, to, to - 0.2 * d + side, colour);
    addSegment(out, to, to - 0.2 * d - side, colour);
}

}  // namespace

App::App(GlContext& context, std::filesystem::path scene, int width, int height, bool interactive)
    : context_(context), interactive_(interactive) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the user's directory
    ImGui::StyleColorsDark();
    if (context_.window()) ImGui_ImplGlfw_InitForOpenGL(context_.window(), true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
    renderer_ = std::make_unique<Renderer>();
    renderer_->resize(width, height);
    load(scene);
}

App::~App() {
    renderer_.reset();
    ImGui_ImplOpenGL3_Shutdown();
    if (context_.window()) ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
}

void App::load(const std::filesystem::path& scene) {
    auto session = std::make_unique<Session>(loadScene(scene));  // throws before anything changes
    scenePath_ = scene;
    session_ = std::move(session);
    selection_.reset();
    rebuildMeshes();
    camera_ = initialCamera(session_->world(), renderer_->width(), renderer_->height());
    for (const SceneWarning& w : session_->scene().warnings) {  // old spellings: on stderr and in the panel
        message_ = "warning: " + scene.string() + ":" + std::to_string(w.line) + ": " + w.message;
        std::fprintf(stderr, "%s\n", message_.c_str());
    }
    for (const ScenePart& part : session_->scene().parts)
        if (part.part.mode != PartMode::Rigid) {  // the panel starts from the first deformable part
            contactLevel_ = part.part.zones.contactLevel;
            restoration_ = restorationIndex(part.part.simulation.restoration.method);
            break;
        }
}

void App::rebuildMeshes() {
    // One mesh per body, in body order (mesh index = body id).
    const World& w = session_->world();
    renderer_->clearParts();
    for (BodyId id = 0; id < w.bodyCount(); ++id) renderer_->addPart(w.part(id));
    normals_.clear();
    for (BodyId id = 0; id < w.bodyCount(); ++id) normals_.emplace_back(w.part(id));
    dirty_.assign(w.bodyCount(), true);
    hierarchies_.clear();
}

void App::frame(double frameSeconds) {
    context_.pollEvents();
    // Scene changes asked for in the last frame happen here, between frames (a bad file leaves
    // the current scene running and says why in the HUD).
    if (requestedScene_) {
        try {
            load(*requestedScene_);
            message_.clear();
        } catch (const std::exception& e) {
            message_ = e.what();
        }
        requestedScene_.reset();
    }
    if (restartRequested_) {
        applySettingsAndRestart();
        restartRequested_ = false;
    }
    auto [fw, fh] = context_.framebufferSize();
    if (context_.window() && fw > 0 && fh > 0) {
        renderer_->resize(fw, fh);
        camera_.width = fw;
        camera_.height = fh;
    }
    ImGui_ImplOpenGL3_NewFrame();
    if (context_.window()) {
        ImGui_ImplGlfw_NewFrame();
    } else {
        ImGuiIO& io = ImGui::GetIO();
        io.DisplaySize = ImVec2(float(renderer_->width()), float(renderer_->height()));
        io.DeltaTime = float(std::max(frameSeconds, 1e-4));
    }
    ImGui::NewFrame();
    if (interactive_) handleInput();
    const std::uint64_t before = session_->steps();
    session_->advance(frameSeconds);
    // Rates in wall time (headless frames are not real time), over at least 0.25 s.
    rateSteps_ += session_->steps() - before;
    ++rateFrames_;
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - rateStart_).count();
    if (elapsed >= 0.25) {
        fps_ = rateFrames_ / elapsed;
        stepsPerSecond_ = double(rateSteps_) / elapsed;
        rateStart_ = now;
        rateSteps_ = 0;
        rateFrames_ = 0;
    }
    drawScene();
    drawHud();
    drawPanels();
    ImGui::Render();
    renderer_->bindTarget();
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (context_.window()) {
        renderer_->blitToWindow(fw, fh);
        context_.swapBuffers();
    }
}

void App::drawScene() {
    const World& w = session_->world();
    renderer_->begin(camera_, kBackground);
    std::vector<int> depths;
    std::vector<Vec3> colours;
    ShownSurface shown;
    for (BodyId id = 0; id < w.bodyCount(); ++id) {
        const Part& part = w.part(id);
        const bool changed = normals_[id].update(part);
        if (!changed && !dirty_[id]) {
            renderer_->drawPart(id, part.pose());
            continue;
        }
        const Vec3 base = partColour(part, w.body(id).motion);
        colours.assign(part.model().massCount(), base);
        if (overlays.zones) {
            part.zoneDepths(depths);
            int deepest = 0;
            for (int d : depths) deepest = std::max(deepest, d);
            for (std::size_t m = 0; m < depths.size(); ++m)
                if (depths[m] >= 0) colours[m] = zoneColour(depths[m], deepest);
        }
        showPart(part, normals_[id].normals(), colours, shown);
        renderer_->upload(id, shown);
        dirty_[id] = false;  // while masses move (and the frame after), update() reports the change
        renderer_->drawPart(id, part.pose());
    }
    if (overlays.hierarchy) {  // the viewer's own copies, in step with the parts' shapes
        if (hierarchies_.empty())
            for (BodyId id = 0; id < w.bodyCount(); ++id) hierarchies_.emplace_back(w.part(id), w.collision().collider(id));
        for (BodyId id = 0; id < w.bodyCount(); ++id) hierarchies_[id].update(w.part(id));
    }
    glDisable(GL_DEPTH_TEST);  // overlays stay visible through the parts
    renderer_->drawLines(overlayLines());
    std::vector<LineVertex> points;
    if (overlays.contacts)
        for (const Contact& c : w.contacts()) points.push_back(lineVertex(c.point, Vec3(1.0, 0.2, 0.9)));
    std::vector<LineVertex> selected;
    if (selection_ && forceTarget_ == 0) points.push_back(lineVertex(w.part(selection_->body).worldPosition(selection_->mass), Vec3(1, 1, 0.2)));
    if (selection_ && forceTarget_ == 1) {
        const Part& p = w.part(selection_->body);
        const Face& f = p.model().mesh.faces[selection_->face];
        for (int k = 0; k < 3; ++k) addSegment(selected, p.worldPosition(f[std::size_t(k)]), p.worldPosition(f[std::size_t(k + 1) % 3]), Vec3(1, 1, 0.2));
    }
    renderer_->drawPoints(points);
    renderer_->drawLines(selected, 2.5f);
    glEnable(GL_DEPTH_TEST);
}

std::vector<LineVertex> App::overlayLines() const {
    const World& w = session_->world();  // drawing reads the world, never changes it
    std::vector<LineVertex> lines;
    const double scale = camera_.distance * 0.02;
    if (overlays.springs)
        for (BodyId id = 0; id < w.bodyCount(); ++id) {
            const Part& p = w.part(id);
            const PartModel& m = p.model();
            for (Index e : p.computedSprings()) {
                const Vec3 a = p.worldPosition(m.springA[e]), b = p.worldPosition(m.springB[e]);
                const bool active = std::abs((a - b).norm() - m.restLength[e]) > p.settings().zones.activityThreshold;
                addSegment(lines, a, b, active ? Vec3(1.0, 0.25, 0.2) : Vec3(1.0, 0.85, 0.25));
            }
        }
    if (overlays.hierarchy)
        for (BodyId id = 0; id < w.bodyCount(); ++id) {
            const PartCollider& collider = hierarchies_[id].collider();
            const Pose& pose = w.part(id).pose();
            auto shown = [&](const auto& node) { return node.depth == overlays.hierarchyDepth || (node.isLeaf() && node.depth < overlays.hierarchyDepth); };
            if (const auto* boxes = collider.boxes())
                for (const auto& node : boxes->nodes())
                    if (shown(node)) addBox(lines, node.volume, pose, Vec3(0.3, 0.85, 0.95));
            if (const auto* spheres = collider.spheres())
                for (const auto& node : spheres->nodes())
                    if (shown(node)) {
                        const Vec3 c = pose.apply(node.volume.centre);
                        addCircle(lines, c, pose.rotate(Vec3::UnitX()), pose.rotate(Vec3::UnitY()), node.volume.radius, Vec3(0.3, 0.85, 0.95));
                        addCircle(lines, c, pose.rotate(Vec3::UnitY()), pose.rotate(Vec3::UnitZ()), node.volume.radius, Vec3(0.3, 0.85, 0.95));
                    }
        }
    if (overlays.partSpheres)  // the broad phase's hierarchies (moving and fixed parts): part spheres (white), their groups (grey)
        for (const Bvh<Sphere>* tree : {&w.collision().broadPhaseTree(), &w.collision().fixedBroadPhaseTree()})
            for (const auto& node : tree->nodes()) {
                const Vec3 colour = node.isLeaf() ? Vec3(0.9, 0.9, 0.9) : Vec3(0.55, 0.55, 0.6);
                addCircle(lines, node.volume.centre, Vec3::UnitX(), Vec3::UnitY(), node.volume.radius, colour);
                addCircle(lines, node.volume.centre, Vec3::UnitY(), Vec3::UnitZ(), node.volume.radius, colour);
                addCircle(lines, node.volume.centre, Vec3::UnitZ(), Vec3::UnitX(), node.volume.radius, colour);
            }
    if (overlays.contacts)
        for (const Contact& c : w.contacts()) addSegment(lines, c.point, c.point + scale * c.normal, Vec3(1.0, 0.2, 0.9));
    if (overlays.assembly)
        for (const AssemblyRule& rule : session_->scene().assemblies) {
            const Pose& primary = w.part(rule.primary).pose();
            const Pose& secondary = w.part(rule.secondary).pose();
            addArrow(lines, primary.apply(rule.primaryVector.origin), primary.apply(rule.primaryVector.end), Vec3(1.0, 0.9, 0.2));
            if (rule.technique == SnapTechnique::VectorSnap)
                addArrow(lines, secondary.apply(rule.secondaryVector.origin), secondary.apply(rule.secondaryVector.end), Vec3(0.4, 0.9, 1.0));
            if (rule.technique == SnapTechnique::ZoneSnap) addArea(lines, rule.area, secondary, Vec3(1.0, 0.55, 0.15));
        }
    if (overlays.coupling && w.coupling().active) {
        const Coupling& c = w.coupling();
        const Vec3 com = w.centreOfMass(c.body);
        const double forceScale = scale * 4.0 / std::max(1.0, w.body(c.body).mass * 9.81);
        addArrow(lines, com, com + forceScale * c.force, Vec3(1.0, 0.3, 0.3));
        addSegment(lines, com, w.grabTarget().apply(w.body(c.body).centreOfMass), Vec3(0.9, 0.9, 0.9));
    }
    return lines;
}

void App::handleInput() {
    ImGuiIO& io = ImGui::GetIO();
    World& w = session_->world();
    // Window points to framebuffer pixels (the camera's units; they differ on HiDPI screens).
    const Vec3 mouse(io.MousePos.x * io.DisplayFramebufferScale.x, io.MousePos.y * io.DisplayFramebufferScale.y, 0.0);
    if (!io.WantCaptureMouse) {
        if (io.MouseWheel != 0.0f) camera_.zoom(std::pow(0.9, io.MouseWheel));
        if (ImGui::IsMouseClicked(0) && (io.KeyCtrl || io.KeyShift)) {
            selection_ = pick(w, camera_.rayThrough(mouse.x(), mouse.y()));
            if (selection_ && io.KeyCtrl && w.body(selection_->body).motion != MotionType::Static) {
                session_->grab(selection_->body, selection_->point);
                dragging_ = true;
                dragPoint_ = selection_->point;
            }
        }
        const ImVec2 delta(io.MouseDelta.x * io.DisplayFramebufferScale.x, io.MouseDelta.y * io.DisplayFramebufferScale.y);
        if (dragging_ && ImGui::IsMouseDown(0)) {
            if (io.KeyAlt) {  // Ctrl+Alt drag: turn the grabbed part about the view axes
                const Mat4 v = camera_.view();
                session_->rotateGrabbed(v.block<1, 3>(1, 0).transpose(), delta.x * 0.01);
                session_->rotateGrabbed(v.block<1, 3>(0, 0).transpose(), delta.y * 0.01);
            } else {
                dragPoint_ = camera_.dragInViewPlane(dragPoint_, delta.x, delta.y);
                session_->dragTo(dragPoint_);
            }
        } else if (ImGui::IsMouseDown(0) && !io.KeyCtrl && !io.KeyShift) {
            camera_.orbit(delta.x, delta.y);
        } else if (ImGui::IsMouseDown(1) || ImGui::IsMouseDown(2)) {
            camera_.pan(delta.x, delta.y);
        }
    }
    if (dragging_ && ImGui::IsMouseReleased(0)) {
        session_->release();
        dragging_ = false;
    }
    if (io.WantCaptureKeyboard) return;
    if (ImGui::IsKeyPressed(GLFW_KEY_SPACE)) session_->paused = !session_->paused;
    if (ImGui::IsKeyPressed(GLFW_KEY_N)) session_->singleStep();
    if (ImGui::IsKeyPressed(GLFW_KEY_F)) camera_ = initialCamera(w, camera_.width, camera_.height);
    if (ImGui::IsKeyPressed(GLFW_KEY_R)) requestedScene_ = scenePath_;  // loaded at the next frame's start
    if (ImGui::IsKeyPressed(GLFW_KEY_F12)) screenshot("flexfit-screenshot.png");
    // Arrow keys, Page Up / Down: a force along -x/+x, +y/-y, +z/-z on the selected mass.
    Vec3 direction = Vec3::Zero();
    if (ImGui::IsKeyDown(GLFW_KEY_LEFT)) direction.x() -= 1;
    if (ImGui::IsKeyDown(GLFW_KEY_RIGHT)) direction.x() += 1;
    if (ImGui::IsKeyDown(GLFW_KEY_UP)) direction.y() += 1;
    if (ImGui::IsKeyDown(GLFW_KEY_DOWN)) direction.y() -= 1;
    if (ImGui::IsKeyDown(GLFW_KEY_PAGE_UP)) direction.z() -= 1;
    if (ImGui::IsKeyDown(GLFW_KEY_PAGE_DOWN)) direction.z() += 1;
    if (selection_ && direction.squaredNorm() > 0 && forceTarget_ == 1)
        session_->setFaceForce(selection_->body, selection_->face, forceMagnitude_ * direction.normalized());
    else if (selection_ && direction.squaredNorm() > 0)
        session_->setMassForce(selection_->body, session_->world().part(selection_->body).model().vertexOf(selection_->mass),
                               forceMagnitude_ * direction.normalized());
    else
        session_->clearMassForce();
}

void App::drawHud() {
    const World& w = session_->world();
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_Always);
    ImGui::SetNextWindowBgAlpha(0.55f);
    ImGui::Begin("##hud", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoInputs | ImGuiWindowFlags_NoSavedSettings);
    std::size_t moving = 0, computed = 0, zones = 0;
    for (BodyId id = 0; id < w.bodyCount(); ++id) {
        moving += w.part(id).movingMasses().size();
        computed += w.part(id).computedSprings().size();
        zones += w.part(id).zoneCount();
    }
    ImGui::Text("%s", scenePath_.filename().c_str());
    ImGui::Text("t = %.3f s   %s", w.time(), session_->paused ? "paused" : "");
    ImGui::Text("FPS %.0f   steps/s %.0f", fps_, stepsPerSecond_);
    ImGui::Text("moving masses %zu", moving);
    ImGui::Text("computed springs %zu", computed);
    ImGui::Text("zones %zu   contacts %zu", zones, w.contacts().size());
    ImGui::Separator();
    for (std::size_t s = 0; s < kStageCount; ++s) ImGui::Text("%-17s %8.1f us", labelOf(Stage(s)), 1e6 * w.profile().lastSeconds[s]);
    ImGui::Text("%-17s %8.1f us", "step", 1e6 * w.profile().lastStepSeconds);
    for (const AssemblyEvent& e : w.assemblyEvents())
        ImGui::Text("assembled '%s' (%s) at %.3f s", e.rule.c_str(), labelOf(e.technique), e.time);
    if (!message_.empty()) ImGui::TextColored(ImVec4(1, 0.8f, 0.3f, 1), "%s", message_.c_str());
    ImGui::End();
}

void App::drawPanels() {
    ImGui::SetNextWindowPos(ImVec2(float(renderer_->width()) - 300, 8), ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(292, 0), ImGuiCond_Always);
    ImGui::SetNextWindowBgAlpha(0.7f);
    ImGui::Begin("Flexfit", nullptr, ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize);
    if (ImGui::CollapsingHeader("Scene", ImGuiTreeNodeFlags_DefaultOpen)) {
        static char path[512] = "";
        if (path[0] == 0) std::snprintf(path, sizeof path, "%s", scenePath_.c_str());
        ImGui::InputText("##path", path, sizeof path);
        ImGui::SameLine();
        if (ImGui::Button("Open")) requestedScene_ = std::filesystem::path(path);
        std::error_code ec;
        if (ImGui::BeginCombo("examples", scenePath_.filename().c_str())) {
            for (const auto& entry : std::filesystem::directory_iterator(scenePath_.parent_path(), ec))
                if (entry.path().extension() == ".toml" && ImGui::Selectable(entry.path().filename().c_str())) {
                    requestedScene_ = entry.path();
                    std::snprintf(path, sizeof path, "%s", entry.path().c_str());
                }
            ImGui::EndCombo();
        }
        if (ImGui::Button(session_->paused ? "Play" : "Pause")) session_->paused = !session_->paused;
        ImGui::SameLine();
        if (ImGui::Button("Step")) session_->singleStep();
        ImGui::SameLine();
        if (ImGui::Button("Reset")) requestedScene_ = scenePath_;
        ImGui::SameLine();
        if (ImGui::Button("Screenshot")) screenshot("flexfit-screenshot.png");
        float speed = float(session_->speed);
        if (ImGui::SliderFloat("speed", &speed, 0.05f, 2.0f, "%.2fx")) session_->speed = speed;
    }
    if (ImGui::CollapsingHeader("Show", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::Checkbox("zones by depth", &overlays.zones);
        ImGui::Checkbox("springs by activity", &overlays.springs);
        ImGui::Checkbox("face hierarchy", &overlays.hierarchy);
        if (overlays.hierarchy) ImGui::SliderInt("depth", &overlays.hierarchyDepth, 0, 16);
        ImGui::Checkbox("part hierarchy (spheres)", &overlays.partSpheres);
        ImGui::Checkbox("contacts", &overlays.contacts);
        ImGui::Checkbox("assembly vectors, areas", &overlays.assembly);
        ImGui::Checkbox("coupling force", &overlays.coupling);
    }
    if (ImGui::CollapsingHeader("Operate", ImGuiTreeNodeFlags_DefaultOpen)) {
        if (selection_)
            ImGui::Text("selected: part %u, mass %u, face %u", selection_->body,  // the mesh file's vertex index
                        session_->world().part(selection_->body).model().vertexOf(selection_->mass), selection_->face);
        else
            ImGui::TextWrapped("Shift+click: select a mass. Ctrl+drag: grab a part.");
        ImGui::RadioButton("force on the mass", &forceTarget_, 0);
        ImGui::SameLine();
        ImGui::RadioButton("on the face", &forceTarget_, 1);
        float magnitude = float(forceMagnitude_);
        if (ImGui::SliderFloat("force", &magnitude, 0.1f, 100.0f, "%.1f N", ImGuiSliderFlags_Logarithmic)) forceMagnitude_ = magnitude;
        const Coupling& c = session_->world().coupling();
        if (c.active) ImGui::Text("coupling |F| %.1f N  |T| %.1f N m", c.force.norm(), c.torque.norm());
    }
    if (ImGui::CollapsingHeader("Deformable parts")) {
        // Restoration and contact level change the running world; the material (the model's
        // spring constants, immutable) restarts the scene.
        bool live = ImGui::Combo("restoration", &restoration_, restorationLabels().data(), int(restorationLabels().size()));
        live |= ImGui::SliderInt("contact level", &contactLevel_, 0, 12);
        if (live) applyLiveSettings();
        ImGui::Combo("material", &material_, kMaterials, 3);
        ImGui::SameLine();
        if (ImGui::Button("restart")) restartRequested_ = true;
    }
    ImGui::End();
}

void App::applyLiveSettings() {
    World& w = session_->world();
    for (BodyId id = 0; id < w.bodyCount(); ++id) {
        if (!w.part(id).deforms()) continue;
        PartSettings settings = w.part(id).settings();
        settings.simulation.restoration.method = restorationAt(restoration_);
        settings.zones.contactLevel = contactLevel_;
        try {
            w.setPartSettings(id, settings);
            message_ = std::string("now: ") + restorationLabels()[std::size_t(restoration_)] + ", contact level " + std::to_string(contactLevel_);
        } catch (const std::exception& e) {
            message_ = e.what();
        }
    }
}

void App::applySettingsAndRestart() {
    Scene& scene = session_->editableScene();
    const Material materials[] = {Material::rigid(), Material::elastic(), Material::superelastic()};
    for (ScenePart& part : scene.parts) {
        if (part.part.mode == PartMode::Rigid) continue;
        part.model = withMaterial(*part.model, materials[material_]);
        part.part.simulation.restoration.method = restorationAt(restoration_);
        part.part.zones.contactLevel = contactLevel_;
    }
    session_->reset();
    selection_.reset();
    rebuildMeshes();
    message_ = std::string("restarted: ") + kMaterials[material_] + ", " + restorationLabels()[std::size_t(restoration_)] + ", level " +
               std::to_string(contactLevel_);
}

void App::screenshot(const std::filesystem::path& file) {
    writePng(file, renderer_->read());
    message_ = "saved " + file.string();
}

}  // namespace flexfit::viewer
