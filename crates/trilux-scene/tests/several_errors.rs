//! The library's side of reporting a file's independent errors together:
//! one error stays the `SceneError::At` it always was; several come as
//! `SceneError::Several`, each error whole, in file order.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test may panic

use trilux_scene::SceneError;

fn scene(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{body}</scene>\n")
}

#[test]
fn one_error_is_the_located_error_it_was() {
    let text = scene("<shape type=\"nosuch\"/>\n");
    let e = trilux_scene::load_str(&text, "one.xml").unwrap_err();
    assert!(matches!(e, SceneError::At { .. }), "{e:?}");
    assert_eq!(e.errors().len(), 1);
    assert_eq!(e.lines(), vec![e.to_string()]);
    assert_eq!(e.location().map(|l| l.line), Some(2));
}

/// Two wrong shapes and a reference to no id: three errors, each an
/// `At` at its own line, displayed one a line.
#[test]
fn independent_errors_come_together_in_file_order() {
    let text = scene(
        "<shape type=\"nosuch\"/>\n<shape type=\"sphere\"><ref id=\"none\"/></shape>\n<shape type=\"cube\"><float name=\"radius\" value=\"1\"/></shape>\n",
    );
    let e = trilux_scene::load_str(&text, "three.xml").unwrap_err();
    let SceneError::Several { errors, more } = &e else {
        panic!("several errors expected: {e:?}");
    };
    assert_eq!(*more, 0);
    let lines: Vec<u32> = errors
        .iter()
        .map(|x| x.location().expect("located").line)
        .collect();
    assert_eq!(lines, [2, 3, 4]);
    assert!(errors.iter().all(|x| matches!(x, SceneError::At { .. })));
    assert_eq!(e.to_string().lines().count(), 3);
    assert_eq!(e.location().map(|l| l.line), Some(2));
}

/// A second `<sensor>` is reported even when the first one is wrong too,
/// and the shapes' errors beside them.
#[test]
fn a_wrong_first_sensor_still_counts_as_the_first() {
    let text = scene(
        "<sensor type=\"perspective\"><float name=\"fov\" value=\"0\"/></sensor>\n<sensor type=\"perspective\"/>\n<shape type=\"nosuch\"/>\n",
    );
    let e = trilux_scene::load_str(&text, "sensors.xml").unwrap_err();
    let lines = e.lines();
    assert_eq!(lines.len(), 3, "{e}");
    assert!(lines[0].contains("fov must lie"), "{e}");
    assert!(lines[1].contains("only one <sensor>"), "{e}");
    assert!(lines[2].contains("nosuch"), "{e}");
}
