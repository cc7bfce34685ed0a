//! What emits: the `--emit` names that make materials, objects and groups
//! emit ([`Scene::set_emission`](crate::scene::Scene::set_emission)), the
//! luminaires an `--ies` file shapes
//! ([`Scene::set_luminaire`](crate::scene::Scene::set_luminaire)), the
//! `--sky` enclosure ([`Scene::add_sky`](crate::scene::Scene::add_sky)), the
//! standard skies of daylighting
//! ([`Scene::add_daylight_sky`](crate::scene::Scene::add_daylight_sky)), the
//! sun ([`Sun`](crate::scene::Sun)) and
//! the units that turn a luminous intensity into the scene's radiosity.

pub(super) mod daylight;
pub(super) mod emit;
pub(super) mod luminaire;
pub(super) mod sky;
pub(super) mod sun;
pub(super) mod units;
