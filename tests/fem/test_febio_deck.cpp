// The FEBio file of a disc problem (febio_deck.hpp) and the orthotropic constants behind its
// fibre tets (orthotropic.hpp). FEBio is not packaged here, so the file is checked by structure,
// read back with tinyxml2: every node, element and set, every material's elasticity rebuilt from
// its engineering constants and axes against D_iso + sum k m m^T of its tet, the plate motion at
// every superior node.
#include "spinesim/fem/elasticity.hpp"
#include "spinesim/fem/fe_space.hpp"
#include "spinesim/fem/febio_deck.hpp"
#include "spinesim/fem/fibres.hpp"
#include "spinesim/fem/orthotropic.hpp"
#include "spinesim/mesh/rigid_plate.hpp"

#include "fibre_fixtures.hpp"

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include <Eigen/Geometry>

#include <map>
#include <random>
#include <set>
#include <sstream>

using namespace spinesim;
using namespace spinesim::fem;

namespace {

Eigen::Vector3d random_unit(std::mt19937& rng) {
  std::normal_distribution<double> n;
  return Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
}

double relative(const Matrix6d& a, const Matrix6d& b) { return (a - b).norm() / b.norm(); }

TEST(Orthotropic, IsotropicElasticityHasItsOwnConstantsInAnyAxes) {
  std::mt19937 rng(1);
  const mesh::IsotropicMaterial m{4.2, 0.45, 1000};
  const Matrix6d D = isotropic_elasticity(m);
  for (int k = 0; k < 5; ++k) {
    const Eigen::Matrix3d Q =
        Eigen::AngleAxisd(0.3 + k, random_unit(rng)).toRotationMatrix();
    const OrthotropicConstants c = orthotropic_constants(D, Q);
    for (double E : {c.E1, c.E2, c.E3}) EXPECT_NEAR(E, 4.2, 1e-12);
    for (double v : {c.v12, c.v23, c.v31}) EXPECT_NEAR(v, 0.45, 1e-12);
    for (double G : {c.G12, c.G23, c.G31}) EXPECT_NEAR(G, 4.2 / (2 * 1.45), 1e-12);
  }
}

TEST(Orthotropic, RotationIsATensorRotation) {
  std::mt19937 rng(2);
  Matrix6d D = isotropic_elasticity({1.0, 0.3, 1000});
  D += fibre_elasticity(random_unit(rng), 50.0);
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.7, random_unit(rng)).toRotationMatrix();
  EXPECT_LT(relative(rotate_elasticity(rotate_elasticity(D, Q), Q.transpose()), D), 1e-14);
  // A fibre along global x seen in axes whose first axis is x: D11 holds it; turned 90° about z,
  // the fibre lies along the local -y axis, so D22 holds it.
  const Matrix6d Dx = fibre_elasticity(Eigen::Vector3d::UnitX(), 10.0);
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Matrix6d L = rotate_elasticity(Dx, Rz);
  EXPECT_NEAR(L(1, 1), 10.0, 1e-12);
  EXPECT_NEAR(L(0, 0), 0.0, 1e-12);
}

TEST(Orthotropic, FibrePairIsOrthotropicInItsAxesAndRoundTrips) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> k(5, 150);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d a1 = random_unit(rng);
    Eigen::Vector3d a2 = random_unit(rng);
    if (trial == 0) a2 = a1;    // one family, twice
    if (trial == 1) a2 = -a1;   // the same line
    const double kf = k(rng);
    Matrix6d D = isotropic_elasticity({4.2, 0.45, 1000});
    D += fibre_elasticity(a1, kf) + fibre_elasticity(a2, kf);
    const Eigen::Matrix3d axes = fibre_pair_axes(a1, a2);
    EXPECT_LT((axes.transpose() * axes - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(axes.determinant(), 1.0, 1e-12);
    const OrthotropicConstants c = orthotropic_constants(D, axes);
    EXPECT_LT(relative(orthotropic_elasticity(c), D), 1e-11) << "trial " << trial;
    // The fibres stiffen along their bisector more than the matrix alone.
    EXPECT_GT(c.E1, 4.2);
  }
}

TEST(Orthotropic, UnequalFamiliesAreRefusedAsNotOrthotropic) {
  const Eigen::Vector3d a1(std::cos(0.5), std::sin(0.5), 0), a2(std::cos(0.5), -std::sin(0.5), 0);
  Matrix6d D = isotropic_elasticity({4.2, 0.45, 1000});
  D += fibre_elasticity(a1, 100.0) + fibre_elasticity(a2, 30.0);
  EXPECT_THROW(orthotropic_constants(D, fibre_pair_axes(a1, a2)), std::invalid_argument);
  // A single fibre off the axes given.
  const Matrix6d F = isotropic_elasticity({4.2, 0.45, 1000}) + fibre_elasticity(a1, 100.0);
  EXPECT_THROW(orthotropic_constants(F, Eigen::Matrix3d::Identity()), std::invalid_argument);
}

// --- the file -------------------------------------------------------------------------------

Eigen::VectorXd numbers(const char* text) {
  std::vector<double> v;
  std::stringstream ss(text ? text : "");
  std::string item;
  while (std::getline(ss, item, ',')) v.push_back(std::stod(item));
  return Eigen::Map<Eigen::VectorXd>(v.data(), Eigen::Index(v.size()));
}

double child_number(const tinyxml2::XMLElement* e, const char* name) {
  const tinyxml2::XMLElement* c = e->FirstChildElement(name);
  EXPECT_NE(c, nullptr) << name;
  return c ? c->DoubleText() : 0.0;
}

/// The global elasticity of a material element of the file.
Matrix6d material_elasticity(const tinyxml2::XMLElement* m) {
  const std::string type = m->Attribute("type");
  if (type == "isotropic elastic")
    return isotropic_elasticity({child_number(m, "E"), child_number(m, "v"), 1000});
  EXPECT_EQ(type, "orthotropic elastic");
  OrthotropicConstants c;
  c.E1 = child_number(m, "E1");
  c.E2 = child_number(m, "E2");
  c.E3 = child_number(m, "E3");
  c.G12 = child_number(m, "G12");
  c.G23 = child_number(m, "G23");
  c.G31 = child_number(m, "G31");
  c.v12 = child_number(m, "v12");
  c.v23 = child_number(m, "v23");
  c.v31 = child_number(m, "v31");
  const tinyxml2::XMLElement* axis = m->FirstChildElement("mat_axis");
  EXPECT_STREQ(axis->Attribute("type"), "vector");
  // FEBio's "vector" axes: e1 = a, e3 = a x d, e2 = e3 x e1 (normalised).
  const Eigen::Vector3d a = numbers(axis->FirstChildElement("a")->GetText()).normalized();
  const Eigen::Vector3d d = numbers(axis->FirstChildElement("d")->GetText()).normalized();
  const Eigen::Vector3d e3 = a.cross(d).normalized();
  c.axes << a, e3.cross(a), e3;
  return orthotropic_elasticity(c);
}

void check_file(int order) {
  SCOPED_TRACE("order " + std::to_string(order));
  const mesh::TetMesh m = test::structured_test_disc(16, 4, 3);
  const mesh::RegionMaterials mat = test::fibre_annulus();
  FebioDeck deck;
  deck.order = order;
  deck.plate_center_mm = Eigen::Vector3d(0.5, 5.0, -0.3);
  deck.motion << 0.01, -0.08, 0.02, 0.004, -0.003, 0.006;
  std::ostringstream os;
  write_febio_deck(os, m, mat, deck);
  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.Parse(os.str().c_str()), tinyxml2::XML_SUCCESS) << doc.ErrorStr();
  const tinyxml2::XMLElement* root = doc.FirstChildElement("febio_spec");
  ASSERT_NE(root, nullptr);
  EXPECT_STREQ(root->Attribute("version"), "4.0");

  const FeSpace space = make_fe_space(m, order);
  const mesh::ElementFibres fibres = mesh::fibre_field(m, mat);
  // Nodes.
  const tinyxml2::XMLElement* mesh_el = root->FirstChildElement("Mesh");
  Eigen::Index nodes = 0;
  for (auto* n = mesh_el->FirstChildElement("Nodes")->FirstChildElement("node"); n;
       n = n->NextSiblingElement("node"), ++nodes) {
    ASSERT_EQ(n->IntAttribute("id"), nodes + 1);
    EXPECT_LT((numbers(n->GetText()) - space.X.row(nodes).transpose()).norm(), 1e-12);
  }
  EXPECT_EQ(nodes, space.num_nodes());
  // Materials by name, then every element once, with its tet's connectivity and elasticity.
  std::map<std::string, const tinyxml2::XMLElement*> materials;
  for (auto* mt = root->FirstChildElement("Material")->FirstChildElement("material"); mt;
       mt = mt->NextSiblingElement("material"))
    materials[mt->Attribute("name")] = mt;
  std::map<std::string, std::string> domain_material;
  for (auto* d = root->FirstChildElement("MeshDomains")->FirstChildElement("SolidDomain"); d;
       d = d->NextSiblingElement("SolidDomain"))
    domain_material[d->Attribute("name")] = d->Attribute("mat");
  std::set<int> seen;
  Eigen::Index fibre_parts = 0;
  for (auto* part = mesh_el->FirstChildElement("Elements"); part;
       part = part->NextSiblingElement("Elements")) {
    EXPECT_STREQ(part->Attribute("type"), order == 1 ? "tet4" : "tet10");
    const std::string name = part->Attribute("name");
    ASSERT_TRUE(domain_material.count(name)) << name;
    ASSERT_TRUE(materials.count(domain_material[name])) << name;
    const Matrix6d D_file = material_elasticity(materials[domain_material[name]]);
    fibre_parts += name.rfind("fibre_", 0) == 0;
    for (auto* e = part->FirstChildElement("elem"); e; e = e->NextSiblingElement("elem")) {
      const int t = e->IntAttribute("id") - 1;
      ASSERT_TRUE(seen.insert(t).second) << "element " << t + 1 << " twice";
      const Eigen::VectorXd conn = numbers(e->GetText());
      ASSERT_EQ(conn.size(), space.nodes_per_element());
      for (int a = 0; a < conn.size(); ++a) EXPECT_EQ(int(conn(a)) - 1, space.elements(t, a));
      Matrix6d D = isotropic_elasticity(mat.at(m.region(t)));
      if (fibres.stiffness_mpa(t) > 0)
        D += fibre_elasticity(fibres.direction_1.row(t).transpose(), fibres.stiffness_mpa(t)) +
             fibre_elasticity(fibres.direction_2.row(t).transpose(), fibres.stiffness_mpa(t));
      EXPECT_LT(relative(D_file, D), 1e-12) << "element " << t + 1;
    }
  }
  EXPECT_EQ(Eigen::Index(seen.size()), m.num_tets());
  EXPECT_EQ(fibre_parts, (m.region.array() == 1).count());  // every annulus tet has fibres
  // Node sets and the plate motion at each superior node (lid: position in the set).
  const Eigen::VectorXi labels = node_surface_labels(space, m);
  std::map<std::string, Eigen::VectorXd> sets;
  for (auto* s = mesh_el->FirstChildElement("NodeSet"); s; s = s->NextSiblingElement("NodeSet"))
    sets[s->Attribute("name")] = numbers(s->GetText());
  EXPECT_EQ(sets["inferior"].size(), (labels.array() == 1).count());
  EXPECT_EQ(sets["superior"].size(), (labels.array() == 2).count());
  for (int k = 0; k < sets["inferior"].size(); ++k) EXPECT_EQ(labels(int(sets["inferior"](k)) - 1), 1);
  int tables = 0;
  for (auto* nd = root->FirstChildElement("MeshData")->FirstChildElement("NodeData"); nd;
       nd = nd->NextSiblingElement("NodeData"), ++tables) {
    EXPECT_STREQ(nd->Attribute("node_set"), "superior");
    const int dof = nd->Attribute("name")[1] - 'x';
    for (auto* v = nd->FirstChildElement("node"); v; v = v->NextSiblingElement("node")) {
      const int node = int(sets["superior"](v->IntAttribute("lid") - 1)) - 1;
      const Eigen::Vector3d u =
          mesh::plate_map(space.X.row(node).transpose() - deck.plate_center_mm) * deck.motion;
      EXPECT_NEAR(v->DoubleText(), u(dof), 1e-14);
    }
  }
  EXPECT_EQ(tables, 3);
}

TEST(FebioDeck, EveryNodeElementMaterialAndPlateValueReadsBack) {
  check_file(1);
  check_file(2);
}

TEST(FebioDeck, BadInputIsRefused) {
  const mesh::TetMesh m = test::structured_test_disc(8, 2, 2);
  std::ostringstream os;
  FebioDeck deck;
  deck.order = 3;
  EXPECT_THROW(write_febio_deck(os, m, test::fibre_annulus(), deck), std::invalid_argument);
  deck.order = 1;
  deck.motion(0) = std::nan("");
  EXPECT_THROW(write_febio_deck(os, m, test::fibre_annulus(), deck), std::invalid_argument);
  mesh::TetMesh unlabelled = m;
  unlabelled.surface.setZero();
  deck.motion.setZero();
  EXPECT_THROW(write_febio_deck(os, unlabelled, test::fibre_annulus(), deck), std::invalid_argument);
}

}  // namespace
