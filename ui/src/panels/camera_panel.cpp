// camera_panel.cpp - drawCameraPanel(): the Camera tab. Scene camera choice, fit / reset, the
// projection's table rows, intrinsics K, look-at, camera JSON copy / paste, and the live model,
// view, projection, MVP and viewport matrices.
#include "panels/panel_common.h"

#include "assets/aov_io.h"
#include "scenegraph/camera_model.h"
#include "scenegraph/transforms.h"

namespace ui {

using namespace panels_detail;

namespace {

// The viewer's frame camera for the current viewport.
sg::FrameCamera viewportCamera(const ViewerState& st) {
    float aspect = float(std::max(st.view.viewportWidth, 1)) / float(std::max(st.view.viewportHeight, 1));
    return sg::makeFrameCamera(st.view.camera.world(), st.viewProjection(), aspect, st.view.camera.distance);
}

// K for the viewport's size, editable: a new K becomes the off-centre frustum with that K
// (sg::projectionFromIntrinsics). Orthographic and oblique cameras have no K.
void drawIntrinsics(ViewerState& st) {
    section("Intrinsics K (computer vision)");
    const int w = st.view.viewportWidth, h = st.view.viewportHeight;
    const sg::CameraModel m = sg::cameraModelOf(viewportCamera(st), w, h);
    if (!m.pinhole) {
        ImGui::TextDisabled("No K: %s projections are not pinhole cameras.", std::string(sg::nameOf(st.projection().type)).c_str());
        return;
    }
    float k[4] = {float(m.K[0][0]), float(m.K[1][1]), float(m.K[0][2]), float(m.K[1][2])};
    ImGui::Text("for %d x %d pixels, origin top-left:", w, h);
    if (ImGui::InputFloat4("fx fy cx cy", k, "%.2f", ImGuiInputTextFlags_EnterReturnsTrue)) {
        sg::Projection p;
        std::string err;
        const sg::Projection cur = st.projection();
        if (sg::projectionFromIntrinsics(k[0], k[1], k[2], k[3], w, h, cur.zNear, cur.zFar, p, &err))
            st.setProjection(p, "");
        else
            st.ui.status = "K not applied: " + err;
    }
    helpMarker(
        "Enter applies: the perspective becomes the general frustum with this K for the current viewport size "
        "(viewer render --intrinsics fx,fy,cx,cy does the same for an image).");
    ImGui::TextDisabled("K = [[%.2f, %.2f, %.2f], [0, %.2f, %.2f], [0, 0, 1]]", m.K[0][0], m.K[0][1], m.K[0][2], m.K[1][1], m.K[1][2]);
}

// Eye, centre and up of the view (lookAt); the orbit camera keeps world +y up (no roll).
void drawLookAt(ViewerState& st) {
    section("Look-at");
    float eye[3], centre[3];
    const sg::vec3 e = st.view.camera.eye(), c = st.view.camera.pivot;
    std::copy(&e.x, &e.x + 3, eye);
    std::copy(&c.x, &c.x + 3, centre);
    bool ch = ImGui::InputFloat3("Eye", eye, "%.3f", ImGuiInputTextFlags_EnterReturnsTrue);
    ch |= ImGui::InputFloat3("Centre", centre, "%.3f", ImGuiInputTextFlags_EnterReturnsTrue);
    const sg::vec3 up = st.view.camera.up();
    ImGui::TextDisabled("Up (%.3f, %.3f, %.3f): the orbit camera keeps world +y up (no roll)", up.x, up.y, up.z);
    if (ch) {
        const sg::vec3 ne(eye[0], eye[1], eye[2]), nc(centre[0], centre[1], centre[2]);
        const float d = glm::length(nc - ne);
        if (!(d > 1e-6f) || !std::isfinite(d)) {
            st.ui.status = "Look-at not applied: eye and centre must differ";
        } else {
            st.view.camera.setFromWorld(glm::inverse(sg::lookAt(ne, nc, sg::vec3(0, 1, 0))), d);
            st.markViewChanged();
        }
    }
}

// Copy / Paste the view as the sidecar's camera JSON (viewer render --camera-json takes it).
void drawCameraJson(ViewerState& st) {
    const int w = st.view.viewportWidth, h = st.view.viewportHeight;
    if (ImGui::Button("Copy camera as JSON")) {
        const sg::FrameCamera fc = viewportCamera(st);
        ImGui::SetClipboardText(assets::aovCameraJson(sg::cameraModelOf(fc, w, h), std::string(sg::nameOf(fc.projection.type)), w, h).c_str());
        st.ui.status = "Camera copied as JSON (" + std::to_string(w) + "x" + std::to_string(h) + "): viewer render --camera-json takes it";
    }
    ImGui::SameLine();
    if (ImGui::Button("Paste camera")) {
        const char* text = ImGui::GetClipboardText();
        assets::AovCamera c;
        std::string err = assets::parseAovCamera(text ? text : "", "clipboard", c);
        if (err.empty()) err = st.setViewFromCameraModel(c.model, c.projection, c.width, c.height);
        st.ui.status = err.empty() ? "Camera pasted" : "Camera not pasted: " + err;
    }
}

}   // namespace

void drawCameraPanel(ViewerState& st) {
    std::vector<sg::NodeId> cams = st.doc.scene.cameras();
    std::string preview = st.doc.scene.valid(st.doc.scene.activeCamera) ? st.doc.scene.node(st.doc.scene.activeCamera).name : "(viewer camera)";
    if (ImGui::BeginCombo("Scene camera", preview.c_str())) {
        for (sg::NodeId c : cams)
            if (ImGui::Selectable(st.doc.scene.node(c).name.c_str(), c == st.doc.scene.activeCamera)) st.useSceneCamera(c);
        ImGui::EndCombo();
    }
    if (ImGui::Button("Fit (F)")) st.fitView(!st.selection().empty());
    ImGui::SameLine();
    if (ImGui::Button("Reset (Home)")) st.resetView();
    ImGui::SameLine();
    if (ImGui::Button("New camera here")) st.addCamera();
    if (st.doc.scene.valid(st.doc.scene.activeCamera)) {
        if (ImGui::Button("Store view in active camera")) st.storeViewInCamera();
        helpMarker("Also done on save, so the scene reopens with this view.");
    }
    ImGui::TextDisabled(cams.empty() ? "No scene camera: edits apply to the viewer's own camera." : "Edits apply to the active scene camera.");

    section("Projection");
    sg::Projection p = st.projection();
    bool ch = false;
    for (const sg::Param<sg::Projection>& row : sg::params<sg::Projection>()) {
        // The type's combo also offers the oblique presets (cavalier, cabinet); the isometric
        // preset turns the camera too, so it is the button below rather than a combo entry. The
        // frustum's four sides (one JSON array, not table rows) come before the clip planes.
        if (row.key == "near") {
            if (p.type == sg::ProjectionType::Perspective && p.useFrustum) {
                ch |= ImGui::DragFloat2("Left / right", &p.left, 0.001f);
                ch |= ImGui::DragFloat2("Bottom / top", &p.bottom, 0.001f);
            }
        }
        if (row.key == "type") {
            sg::Param<sg::Projection> type = row;
            std::erase_if(type.choices, [](const sg::ParamChoice& c) {
                sg::AxonometricPreset preset;
                return sg::parseName(c.name, preset);
            });
            ch |= paramWidget(st, "camera", type, p);
            continue;
        }
        ch |= paramWidget(st, "camera", row, p);
    }
    if (ImGui::Button("Isometric view")) st.viewAlong(AxisView::Isometric);
    tooltip("Orthographic, looking along (-1,-1,-1) at the pivot: the three axes equally foreshortened (View > Axis view > Isometric)");
    if (ch) {
        p.zFar = std::max(p.zFar, p.zNear * 1.001f);
        st.setProjection(p, "projection");
    }
    ImGui::TextDisabled("Zoom factor %.3f  (orthographic / oblique)", st.view.camera.orthoScale);
    drawIntrinsics(st);
    drawLookAt(st);
    drawCameraJson(st);

    section("Live matrices");
    float aspect = float(std::max(st.view.viewportWidth, 1)) / float(std::max(st.view.viewportHeight, 1));
    sg::FrameCamera fc = viewportCamera(st);
    const sg::mat4 model = st.doc.scene.valid(st.doc.selected) ? st.doc.scene.world(st.doc.selected) : sg::mat4(1.0f);
    if (st.doc.scene.valid(st.doc.selected)) {
        ImGui::Text("Model (world of '%s')", st.doc.scene.node(st.doc.selected).name.c_str());
        matrixTable("model", model);
    } else {
        ImGui::TextDisabled("Model: select a node (identity below)");
    }
    ImGui::TextUnformatted("View");
    matrixTable("view", fc.view);
    ImGui::TextUnformatted("Model-view");
    matrixTable("modelview", fc.view * model);
    ImGui::Text("Projection (aspect %.3f)", aspect);
    matrixTable("proj", fc.proj);
    ImGui::TextUnformatted("MVP = projection x view x model");
    matrixTable("mvp", fc.proj * fc.view * model);
    // Viewport: NDC -> window pixels (origin bottom-left, depth 0..1), as glViewport + glDepthRange.
    const float vw = float(st.view.viewportWidth), vh = float(st.view.viewportHeight);
    sg::mat4 vp(1.0f);
    vp[0][0] = 0.5f * vw;
    vp[1][1] = 0.5f * vh;
    vp[2][2] = 0.5f;
    vp[3] = sg::vec4(0.5f * vw, 0.5f * vh, 0.5f, 1.0f);
    ImGui::Text("Viewport (%d x %d, depth 0..1)", st.view.viewportWidth, st.view.viewportHeight);
    matrixTable("viewport", vp);
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
    ImGui::TextWrapped("Eye (%.2f, %.2f, %.2f)  pivot (%.2f, %.2f, %.2f)  distance %.3f", fc.eye.x, fc.eye.y, fc.eye.z, st.view.camera.pivot.x,
                       st.view.camera.pivot.y, st.view.camera.pivot.z, st.view.camera.distance);
    ImGui::PopStyleColor();
}

}   // namespace ui
