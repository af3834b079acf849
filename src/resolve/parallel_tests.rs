//! The objects resolved alone on the workers give what the serial resolver
//! gives: the same findings in the same order, the same geometries, the same
//! unused parameters, on any number of threads.

use super::{Pass, Resolved, named, resolve_in};
use crate::diag::{Code, Diagnostics};
use crate::span::SourceFile;
use crate::syntax::{self, Limits};
use crate::test_threads::on_threads;

/// Kinds of object (by `i % 20`) whose resolution needs another object.
const NEEDS_ANOTHER: [usize; 7] = [2, 4, 6, 14, 15, 18, 19];

/// `count` objects named `o{i}`, one of twenty kinds by `i % 20`: plain
/// primitives, ones in (nested, undefined, cyclic) coordinate systems,
/// references forward and back, transforms of themselves, of later objects
/// and of a replicate's member, and numbers with unknown names, wrong kinds,
/// wrong axes and bad values; every 700th object repeats a name.
fn objects(count: usize) -> String {
    let mut xml = String::from(
        "<geometry version=\"1\">
  <parameters>
    <parameter name=\"r\" value=\"0.3\"/>
    <parameter name=\"unused\" value=\"1\"/>
    <parameter name=\"h\" value=\"r * 2\"/>
    <parameter name=\"ca\" value=\"cb + 1\"/>
    <parameter name=\"cb\" value=\"ca\"/>
    <parameter name=\"late\" value=\"2\"/>
    <parameter name=\"unused_too\" value=\"3\"/>
  </parameters>
  <basis_coordinate>
    <coordinate name=\"X\"><value x1=\"0\" x2=\"1\"/></coordinate>
    <coordinate name=\"Y\"><value y1=\"0\" y2=\"1\"/></coordinate>
  </basis_coordinate>
  <coordinate_system name=\"lcs\" cs=\"outer\"><origin point=\"org\"/><rotation z=\"90\"/></coordinate_system>
  <coordinate_system name=\"outer\"><origin x=\"0\" y=\"0\" z=\"5\"/></coordinate_system>
  <coordinate_system name=\"loop1\" cs=\"loop2\"/>
  <coordinate_system name=\"loop2\" cs=\"loop1\"/>
  <point name=\"org\"><value x=\"1\" y=\"2\" z=\"3\"/></point>
",
    );
    for i in 0..count {
        let name = if i % 700 == 699 {
            format!("o{}", i - 1)
        } else {
            format!("o{i}")
        };
        let (x, y, z) = (i % 17, i / 17 % 13, i / 221);
        let center = format!("<center x=\"{x}\" y=\"{y}\" z=\"{z}\"/>");
        let object = match i % 20 {
            0 => format!("<sphere name=\"{name}\">{center}<radius value=\"r\"/></sphere>"),
            1 => {
                format!("<sphere name=\"{name}\" cs=\"lcs\">{center}<radius value=\"h\"/></sphere>")
            }
            2 => format!(
                "<sphere name=\"{name}\"><center point=\"o{}\"/><radius value=\"0.2\"/></sphere>",
                i + 1
            ),
            3 => format!("<point name=\"{name}\"><value x=\"{x}\" y=\"{y}\" z=\"{z}\"/></point>"),
            4 => format!(
                "<transform name=\"{name}\" ref=\"o{}\"><shift x=\"0.5\"/></transform>",
                i + 1
            ),
            5 => format!(
                "<parallelepiped name=\"{name}\"><first_point x=\"{x}\" y=\"{y}\" z=\"{z}\"/><second_point x=\"{x}.5\" y=\"{y}.5\" z=\"{z}.5\"/></parallelepiped>"
            ),
            6 => format!("<transform name=\"{name}\" ref=\"{name}\"><shift z=\"1\"/></transform>"),
            7 => format!(
                "<torus name=\"{name}\">{center}<major_radius value=\"0.5\"/><minor_radius value=\"rr/2\"/></torus>"
            ),
            8 => format!("<sphere name=\"{name}\">{center}<radius value=\"-1\"/></sphere>"),
            9 => format!(
                "<ellipsoid name=\"{name}\">{center}<semi_axes x=\"0.5\" y=\"o0\" z=\"x1\"/></ellipsoid>"
            ),
            10 => format!(
                "<sphere name=\"{name}\"><center x=\"x2\" y=\"x1\" z=\"{z}\"/><radius value=\"r\"/></sphere>"
            ),
            11 => {
                format!("<sphere name=\"{name}\" cs=\"lsc\">{center}<radius value=\"r\"/></sphere>")
            }
            12 => format!(
                "<sphere name=\"{name}\" cs=\"loop1\">{center}<radius value=\"r\"/></sphere>"
            ),
            13 => format!(
                "<point name=\"{name}\"><value x=\"{x}\" y=\"{y}\" z=\"{z}\"/><value x=\"{x}\" y=\"{y}\"/></point>"
            ),
            14 => format!(
                "<sphere name=\"{name}\"><center point=\"o{}\"/><radius value=\"r\"/></sphere>",
                i - 1
            ),
            15 => format!(
                "<sphere name=\"{name}\"><center point=\"o{}[2]\"/><radius value=\"r\"/></sphere>",
                i - 2
            ),
            16 if i % 40 == 16 => {
                format!("<vertex name=\"{name}\" x=\"{x}\" y=\"{y}\" z=\"{z}\"/>")
            }
            16 => {
                format!("<vertex name=\"{name}\" x=\"{x} + 1 / (r - 0.3)\" y=\"{y}\" z=\"{z}\"/>")
            }
            17 => format!(
                "<edge name=\"{name}\" begin=\"o{}\" end=\"o{}\"/>",
                i - 1,
                i - 17
            ),
            18 => format!(
                "<replicate name=\"{name}\" ref=\"o{}\" count=\"3\"><shift x=\"late\"/></replicate>",
                i - 18
            ),
            _ => format!(
                "<transform name=\"{name}\" ref=\"o{}[2]\"><rotate z=\"90\"/></transform>",
                i - 1
            ),
        };
        xml.push_str("  ");
        xml.push_str(&object);
        xml.push('\n');
        if i % 20 == 0 {
            xml.push_str(&format!(
                "  <subdomain name=\"d{i}\" area=\"r\"><solid ref=\"{name}\"/></subdomain>\n"
            ));
        }
    }
    xml.push_str(
        "  <transform name=\"cyc_a\" ref=\"cyc_b\"><shift x=\"1\"/></transform>
  <transform name=\"cyc_b\" ref=\"cyc_a\"><shift x=\"1\"/></transform>
</geometry>
",
    );
    xml
}

/// Resolution's findings (in the order made, not sorted), the resolved
/// document and the number of objects resolved alone.
fn resolved(xml: &str, pass: Pass, threads: usize) -> (Diagnostics, Resolved, usize) {
    let source = SourceFile::new("many.xml".to_string(), xml.to_string());
    let root = syntax::parse(&source, &Limits::default()).expect("parses");
    let mut read = Diagnostics::default();
    let doc = crate::doc::build(&source, &root, &mut read);
    assert!(read.items.is_empty(), "{:?}", read.items.first());
    let mut diags = Diagnostics::default();
    let (resolved, alone) =
        on_threads(threads, || resolve_in(&source, &doc, &[], &mut diags, pass));
    let names = doc.objects.iter().map(|object| object.name.text.clone());
    (diags, named(resolved, names), alone)
}

#[test]
fn objects_resolved_alone_give_the_serial_findings_and_geometries_on_any_thread_count() {
    let count = 3_000;
    let xml = objects(count);
    let (serial, expected, none) = resolved(&xml, Pass::Serial, 1);
    assert_eq!(none, 0);
    let codes =
        |diags: &Diagnostics, code: Code| diags.items.iter().filter(|d| d.code == code).count();
    // Self-transforms (150), the cs loop, the parameter cycle and the
    // transform pair (once, where the chain comes back); spheres in the
    // looping system fail without a finding of their own.
    assert_eq!(codes(&serial, Code::ReferenceCycle), 150 + 1 + 1 + 1);
    // rr and the system lsc (150 each).
    assert_eq!(codes(&serial, Code::UndefinedName), 150 + 150);
    // A sphere as a number, x1 outside a coordinate, a sphere as an edge's end.
    assert_eq!(codes(&serial, Code::WrongKind), 150 + 150 + 150);
    assert_eq!(codes(&serial, Code::WrongAxis), 150);
    assert_eq!(codes(&serial, Code::NonPositiveSize), 150);
    assert_eq!(codes(&serial, Code::NonFiniteValue), 75);
    assert_eq!(codes(&serial, Code::IndexOutOfRange), 150);
    assert_eq!(codes(&serial, Code::PointValueShape), 150);
    assert_eq!(codes(&serial, Code::AreaIn3d), 150);
    assert_eq!(codes(&serial, Code::DuplicateName), 4);
    let unused: Vec<&str> = (serial.items.iter())
        .filter(|d| d.code == Code::UnusedParameter)
        .map(|d| d.message.as_str())
        .collect();
    assert_eq!(
        unused,
        [
            "parameter 'unused' is never used",
            "parameter 'unused_too' is never used"
        ]
    );
    let solids = (expected.objects.iter())
        .filter(|o| matches!(o.geometry, Some(super::Geometry::Solid(_))))
        .count();
    // Kinds 0, 1, 2, 4, 5, 15 and 19 of each twenty are valid solids.
    assert_eq!(solids, 7 * 150);

    // Of the `count` objects, the origin point and the transform pair, all
    // are resolved alone but those that need another (the pair too) and the
    // origin point, which the coordinate systems resolved first.
    let needing = (0..count)
        .filter(|i| NEEDS_ANOTHER.contains(&(i % 20)))
        .count()
        + 2;
    assert_eq!(expected.objects.len(), count + 3);
    for threads in [1, 2, 3] {
        let (diags, resolved, alone) = resolved(&xml, Pass::Parallel, threads);
        assert_eq!(alone, count + 3 - needing - 1, "{threads} threads");
        assert_eq!(diags.items, serial.items, "{threads} threads");
        assert_eq!(resolved.objects, expected.objects, "{threads} threads");
        assert_eq!(resolved.parameters, expected.parameters);
        assert_eq!(resolved.subdomain_areas, expected.subdomain_areas);
    }
}

#[test]
fn a_file_of_few_objects_is_resolved_serially() {
    let xml = objects(100);
    let (serial, expected, _) = resolved(&xml, Pass::Serial, 1);
    let (diags, resolved, alone) = resolved(&xml, Pass::Parallel, 2);
    assert_eq!(alone, 0);
    assert_eq!(diags.items, serial.items);
    assert_eq!(resolved.objects, expected.objects);
}
