//! The Cylinder section: the diameter of a cylinder job and what the machine makes of it.

use crate::document::Document;

impl super::App {
    /// The Cylinder section; a changed diameter places the strips again (when idle).
    pub(super) fn cylinder_ui(&mut self, ui: &mut egui::Ui) {
        let words = cylinder_words(self.session.doc(), &self.session.strips());
        let settings = self.session.doc().settings.clone();
        let Some(cmd) = self.panels.editors.cylinder_ui(ui, &settings, &words) else {
            return;
        };
        if self.execute(cmd).is_ok() && !self.is_busy() && !self.session.doc().geometries.is_empty()
        {
            // strips of the new height (or the machine's fields again)
            self.replace_fields(ui.ctx());
        }
    }
}

/// The cylinder job in an operator's words: the strips in focus (`strips`, as
/// [`crate::pipeline::cylinder_strips`] found them), or why the machine cannot mark it, or how
/// to start one.
pub fn cylinder_words(doc: &Document, strips: &crate::pipeline::Strips) -> String {
    match strips {
        Ok(None) => "A flat job. To mark around a tube, ring or bottle on the rotary A axis, give \
                     its diameter: the drawing is then its unrolled surface, x along the axis and \
                     y around it."
            .into(),
        Ok(Some((c, strip))) => format!(
            "Cylinder ⌀{} mm: strips in focus are {strip:.2} mm high (depth of focus {} mm); \
             {:.2} mm around. The part turns to each strip's angle; the scanner marks it from \
             above.",
            crate::geom::format_mm(c.diameter_mm, 3),
            doc.profile
                .scanner
                .depth_of_focus_mm
                .map_or("?".into(), |v| crate::geom::format_mm(v, 3)),
            c.circumference_mm(),
        ),
        Err(why) => format!(
            "Cylinder ⌀{} mm cannot be marked: {why}",
            doc.settings
                .cylinder
                .map_or(String::new(), |c| crate::geom::format_mm(c.diameter_mm, 3))
        ),
    }
}
