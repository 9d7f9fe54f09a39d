"""The scenes shipped with gearbody: one TOML scenario per system of the paper (data only).

Installed as the data package ``gearbody_scenes``; gearbody finds them with
``gearbody.model.scenes`` (``list_scenes``, ``scene_path``)."""
