//! Departures that keep the course's behaviour: a submission that reaches the course's answers
//! another way is named as such and not charged (`docs/weekly-checks.md`, "What a project may
//! change").
//!
//! The rule: a function is judged by what the course's own code gets from it where the course
//! uses it. The grader gives every input the course's scenes give (the lens, the scene's
//! background colour, the random numbers), in the submission's own convention when it can tell
//! which one that is, and a function whose work the submission has moved into its caller is
//! judged through that caller. Two kinds:
//!
//! - **A convention the driver follows** (an answer's `"departures"` list, codes this module
//!   words: [`listed`]): `init_camera(aperture, focus)` instead of `init_camera(defocus_angle,
//!   focus)` (week 10's task 2 asks for it) is given the course's lens as its aperture
//!   `2 focus tan(angle / 2)`, and the answer says so. The codes are only words: what the
//!   submission answers is judged as always.
//! - **Work moved between functions** ([`schlick_in_material`], applied by
//!   [`run_week`](super::run::run_week) after a week's checks ran): Schlick's random
//!   choice made in `Dielectric.scattering` instead of in `refract`. `refract` then answers
//!   exactly as the catalogued `refract_without_schlick` (reflecting only under total internal
//!   reflection) while the material, judged by what it does (`dielectric`, and
//!   `dielectric-choice`'s count of reflections against Schlick's probability), is the
//!   course's: `refract` is passed with the departure named, instead of being charged for what
//!   the material does right.
//!
//! A scene's background colour is the third case of the rule, and needs neither: the driver
//! gives the scene the course's colour (0.01 grey) explicitly, so an integrator returning the
//! scene's own colour on a miss answers the course's whatever its class's default.

/// A departure: the name it is reported under, and what it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Departure {
    /// The name (reported as a mistake's name is, with the standing
    /// [`Departure`](super::samplers::Standing::Departure)).
    pub name: &'static str,
    /// What the submission does, in words.
    pub says: &'static str,
}

/// What each departure code of an answer means, in words.
const CODES: &[(&str, &str)] = &[(
    "aperture",
    "init_camera takes the lens's aperture (its diameter) instead of the defocus angle (week 10's task 2): it was given the course's lens as the aperture 2 focus tan(angle / 2), and its answers are judged as the course's",
)];

/// The words of the departure codes `answer` lists (its `"departures"`), known codes only, as
/// notes of the function (`departure that keeps the course's behaviour: ...`).
pub fn listed(answer: &serde_json::Value) -> Vec<String> {
    let Some(list) = answer
        .get("departures")
        .and_then(serde_json::Value::as_array)
    else {
        return Vec::new();
    };
    list.iter()
        .filter_map(serde_json::Value::as_str)
        .filter_map(|code| CODES.iter().find(|(c, _)| *c == code))
        .map(|(_, words)| format!("departure that keeps the course's behaviour: {words}"))
        .collect()
}

/// Schlick's choice moved from `refract` into `Dielectric.scattering`.
pub const SCHLICK_IN_MATERIAL: Departure = Departure {
    name: "schlick_in_dielectric",
    says: "Schlick's random choice is made in Dielectric.scattering, not in refract: refract reflects only under total internal reflection, and the material reflects with Schlick's probability as the course's does (dielectric and dielectric-choice pass)",
};

/// Whether a failing `refract` is [`SCHLICK_IN_MATERIAL`]: the catalogued mistakes its answers
/// fit include `refract_without_schlick`, and the material passes both of its checks
/// (`dielectric`, `dielectric-choice`).
pub fn schlick_in_material(
    refract_fits: &[&str],
    dielectric_passed: bool,
    choice_passed: bool,
) -> Option<Departure> {
    (refract_fits.contains(&"refract_without_schlick") && dielectric_passed && choice_passed)
        .then_some(SCHLICK_IN_MATERIAL)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// Schlick's choice in the material is a departure only when refract fits
    /// refract_without_schlick and the material passes both of its checks.
    #[test]
    fn schlick_moved_into_the_material_is_a_departure_only_when_the_material_is_right() {
        let fits = ["refract_without_schlick"];
        assert_eq!(
            schlick_in_material(&fits, true, true),
            Some(SCHLICK_IN_MATERIAL)
        );
        assert_eq!(schlick_in_material(&fits, true, false), None);
        assert_eq!(schlick_in_material(&fits, false, true), None);
        assert_eq!(
            schlick_in_material(&["schlick_wrong_cosine"], true, true),
            None
        );
        assert_eq!(schlick_in_material(&[], true, true), None);
    }

    #[test]
    fn only_known_departure_codes_are_worded() {
        let a = json!({"departures": ["aperture", "made up by the submission", 3]});
        let words = listed(&a);
        assert_eq!(words.len(), 1);
        assert!(
            words[0].starts_with(
                "departure that keeps the course's behaviour: init_camera takes the lens's aperture"
            ),
            "{words:?}"
        );
        assert!(listed(&json!({"value": 1.0})).is_empty());
        assert!(listed(&json!({"departures": "aperture"})).is_empty());
    }
}
