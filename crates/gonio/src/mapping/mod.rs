//! Diagram → mapping: the Havran–Dmitriev–Seidel map F = M_E ∘ M_D ∘ M_C ∘ M_B.
#![allow(missing_docs)]
/// Placeholder until the mapping lands.
pub struct HemisphereMap;
/// Placeholder until the mapping lands.
pub struct SphereMap;
