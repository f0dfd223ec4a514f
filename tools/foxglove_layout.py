"""Write the Foxglove layout shipped in docs/foxglove/ (docs/foxglove.md), built with the
Foxglove SDK's typed layout API so that its keys are the ones Foxglove reads.

    pip install foxglove-sdk   # not a dependency of paper-replay: only this script needs it
    python tools/foxglove_layout.py docs/foxglove/catch_layout.json
"""

from __future__ import annotations

import sys

import foxglove.layouts as L


def catch_layout() -> L.Layout:
    urdf = L.BaseRendererUrdfLayerSettings(
        instance_id="robot",
        layer_id="foxglove.Urdf",
        label="robot (/robot_description)",
        source_type="topic",
        topic="/robot_description",
        display_mode="visual",
    )
    grid = L.BaseRendererGridLayerSettings(
        instance_id="grid", layer_id="foxglove.Grid", frame_id="world", size=4, divisions=40
    )
    three = L.ThreeDeePanel(
        title="3-D: arm (URDF + /tf), ball and scene (/scene)",
        config=L.ThreeDeeConfig(
            follow_tf="world",
            follow_mode="follow-none",
            layers={"robot": urdf, "grid": grid},
            topics={"/scene": L.BaseRendererSceneUpdateTopicSettings(visible=True)},
            camera_state=L.ThreeDeeCameraState(
                distance=3.2, phi=65.0, theta_offset=-40.0, target=[1.1, 0.0, 0.6], perspective=True
            ),
        ),
    )

    def image(view: str) -> L.ImagePanel:
        return L.ImagePanel(
            title=f"stereo {view}",
            config=L.ImageConfig(
                image_mode=L.ImageModeConfig(image_topic=f"/camera/stereo/{view}")
            ),
        )

    plot = L.PlotPanel(
        title="ball height and joint angles",
        config=L.PlotConfig(
            paths=[
                L.PlotSeries(value="/object/state.position[2]", label="ball z (m)", enabled=True),
                L.PlotSeries(
                    value="/joint_states.joints[0].position", label="J1 (rad)", enabled=True
                ),
                L.PlotSeries(
                    value="/joint_states.joints[1].position", label="J2 (rad)", enabled=True
                ),
                L.PlotSeries(
                    value="/joint_states.joints[3].position", label="J4 (rad)", enabled=True
                ),
            ],
            show_legend=True,
        ),
    )
    log = L.LogPanel(title="events (/log)", config=L.LogConfig(topic_to_render="/log"))
    right = L.SplitContainer(
        direction="column",
        items=[
            L.SplitItem(
                proportion=1,
                content=L.SplitContainer(
                    direction="row",
                    items=[
                        L.SplitItem(proportion=1, content=image("cam0")),
                        L.SplitItem(proportion=1, content=image("cam1")),
                    ],
                ),
            ),
            L.SplitItem(proportion=1, content=plot),
            L.SplitItem(proportion=1, content=log),
        ],
    )
    return L.Layout(
        content=L.SplitContainer(
            direction="row",
            items=[
                L.SplitItem(proportion=3, content=three),
                L.SplitItem(proportion=2, content=right),
            ],
        )
    )


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "docs/foxglove/catch_layout.json"
    with open(out, "w") as f:
        f.write(catch_layout().to_json())
        f.write("\n")
    print(out)
